#!/usr/bin/env bash
# The README's first command: install what is missing, build the tool, run the built-in demo
# (a simulated push with occlusion estimated by the CP, SDF and QS graphs; a few seconds).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release -DPUSHGRAPH_BUILD_TESTS=OFF -DPUSHGRAPH_BUILD_BENCH=OFF \
  -DPUSHGRAPH_BUILD_PYTHON=ON >/dev/null
cmake --build build --target pushgraph pushgraph_python -j"$(nproc)"
# The Python package into the interpreter's packages (/usr/local/lib/python3.11/dist-packages):
# afterwards `python3 -c "import pushgraph"` works anywhere.
cmake --install build --component python >/dev/null
mkdir -p out
./build/tools/pushgraph demo --svg out/demo.svg  # `demo --geometry`: the exact-geometry demo
