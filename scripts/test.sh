#!/usr/bin/env bash
# The README's second command: build everything (libraries, tool, tests, benchmarks) and run
# every test. With --sanitize, builds the tests with AddressSanitizer and
# UndefinedBehaviorSanitizer in build-asan/ and runs the geometry tests under them.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh
jobs=$(nproc)
if [ "${1:-}" = "--sanitize" ]; then
  cmake -S . -B build-asan -DCMAKE_BUILD_TYPE=RelWithDebInfo -DPUSHGRAPH_SANITIZE=ON -DPUSHGRAPH_BUILD_BENCH=OFF >/dev/null
  cmake --build build-asan --target pushgraph_geometry_tests -j"$jobs"
  export ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
  PUSHGRAPH_TEST_SCALE=0.25 ctest --test-dir build-asan -L geometry --output-on-failure -j"$jobs"
  exit 0
fi
# EXAMPLES explicitly: a build/ configured by quickstart.sh (tests off) cached it OFF.
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release -DPUSHGRAPH_BUILD_TESTS=ON -DPUSHGRAPH_BUILD_EXAMPLES=ON -DPUSHGRAPH_BUILD_BENCH=ON \
  -DPUSHGRAPH_BUILD_PYTHON=ON >/dev/null
cmake --build build -j"$jobs"
ctest --test-dir build --output-on-failure -j"$jobs"
bash scripts/check-install.sh build
