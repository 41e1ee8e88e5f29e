#!/usr/bin/env bash
# The README's first command: install what is missing, build the tool, run the built-in demo
# (a simulated push with occlusion estimated by the CP, SDF and QS graphs; a few seconds).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release -DPUSHGRAPH_BUILD_TESTS=OFF -DPUSHGRAPH_BUILD_BENCH=OFF >/dev/null
cmake --build build --target pushgraph -j"$(nproc)"
mkdir -p out
./build/tools/pushgraph demo --svg out/demo.svg  # `demo --geometry`: the exact-geometry demo
