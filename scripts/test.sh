#!/usr/bin/env bash
# The README's second command: build everything (libraries, tool, tests, benchmarks) and run
# every test. With --sanitize, builds the tests with AddressSanitizer and
# UndefinedBehaviorSanitizer in build-asan/ and runs the geometry tests under them.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh
jobs=$(nproc)
if [ "${1:-}" = "--sanitize" ] || [ "${1:-}" = "--sanitize-all" ]; then
  # --sanitize (CI): the geometry tests. --sanitize-all: also limit_surface, push, io and the tool's
  # tests (115 more; a cold build of the sanitized estimation and io code takes about 17 min on 2
  # cores, too long for CI's budget beside the main stage; run it before a release).
  targets=(pushgraph_geometry_tests)
  labels=geometry
  if [ "${1:-}" = "--sanitize-all" ]; then
    targets+=(pushgraph_limit_surface_tests pushgraph_push_tests pushgraph_io_tests pushgraph_tools_tests)
    labels="geometry|limit_surface|push|io|tools"
  fi
  cmake -S . -B build-asan -DCMAKE_BUILD_TYPE=RelWithDebInfo -DPUSHGRAPH_SANITIZE=ON -DPUSHGRAPH_BUILD_BENCH=OFF >/dev/null
  cmake --build build-asan --target "${targets[@]}" -j"$jobs"
  export ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
  PUSHGRAPH_TEST_SCALE=0.25 ctest --test-dir build-asan -L "$labels" --output-on-failure -j"$jobs"
  exit 0
fi
# EXAMPLES explicitly: a build/ configured by quickstart.sh (tests off) cached it OFF.
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release -DPUSHGRAPH_BUILD_TESTS=ON -DPUSHGRAPH_BUILD_EXAMPLES=ON -DPUSHGRAPH_BUILD_BENCH=ON \
  -DPUSHGRAPH_BUILD_PYTHON=ON >/dev/null
cmake --build build -j"$jobs"
ctest --test-dir build --output-on-failure -j"$jobs"
bash scripts/check-install.sh build
