#!/usr/bin/env bash
# Installs the build tree into a temporary prefix outside the source tree, then configures,
# builds and runs examples/consumer and the examples (examples/, as their CTest tests, reading
# the installed data) against it: proof that find_package(pushgraph) works.
set -euo pipefail
cd "$(dirname "$0")/.."
build=${1:-build}
prefix=$(mktemp -d /tmp/pushgraph-prefix.XXXXXX)
work=$(mktemp -d /tmp/pushgraph-consumer.XXXXXX)
trap 'rm -rf "$prefix" "$work"' EXIT
cmake --install "$build" --prefix "$prefix" >/dev/null
cmake -S examples/consumer -B "$work" -DCMAKE_PREFIX_PATH="$prefix" -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build "$work" -j"$(nproc)" >/dev/null
"$work/consumer"
(cd "$work" && "$prefix/bin/pushgraph" demo --svg "$work/demo.svg" >/dev/null)  # finds $prefix/share/pushgraph
cmake -S examples -B "$work/examples" -DCMAKE_PREFIX_PATH="$prefix" -DCMAKE_BUILD_TYPE=Release \
  -DPUSHGRAPH_EXAMPLES_DATA_DIR="$prefix/share/pushgraph" >/dev/null
cmake --build "$work/examples" -j"$(nproc)" >/dev/null
ctest --test-dir "$work/examples" --output-on-failure
# The Python package, when built: importable from the installed prefix alone.
if grep -q '^PUSHGRAPH_BUILD_PYTHON:BOOL=ON' "$build/CMakeCache.txt"; then
  site=$(ls -d "$prefix"/lib/python3*/*-packages | head -1)
  py=$(grep "^Python3_EXECUTABLE" "$build/CMakeCache.txt" | cut -d= -f2)
  (cd "$work" && PYTHONPATH="$site" "$py" -c "import pushgraph; assert pushgraph.Shape.box(1, 2).area == 2")
fi
echo "check-install: consumer project, examples, installed tool and Python package passed (prefix $prefix)"
