#!/usr/bin/env bash
# The README's second command: build everything (libraries, tool, tests, benchmarks) and run
# every test. With --sanitize, builds every test with clang, AddressSanitizer and
# UndefinedBehaviorSanitizer in build-sanitize/ and runs them (scaled down) under them.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh
jobs=$(nproc)
if [ "${1:-}" = "--sanitize" ]; then
  # The tests (geometry, limit_surface, push, io, graph, evaluation, the tool) built by clang with
  # ASan + UBSan in build-sanitize/ (scripts/sanitize-build.sh, shared with the fuzzers), iteration
  # counts and recording subsets scaled by PUSHGRAPH_TEST_SCALE. Left out: the docs tests and the
  # examples (the main stage runs them; their code is the libraries'), and the tests listed, with
  # the rule and the reasons, in scripts/sanitizer-skip.txt.
  bash scripts/sanitize-build.sh
  export ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
  export LSAN_OPTIONS="suppressions=$PWD/fuzz/lsan.supp"
  mapfile -t skipped < <(sed -e 's/#.*//' -e 's/[[:space:]]//g' scripts/sanitizer-skip.txt | grep -v '^$')
  # A name that no longer exists (a renamed test) would leave its replacement in: say so.
  known=$(ctest --test-dir build-sanitize -N -LE docs | sed -n 's/^ *Test *#[0-9]*: //p')
  for name in "${skipped[@]}"; do
    grep -qxF "$name" <<< "$known" || { echo "scripts/sanitizer-skip.txt: no test named $name" >&2; exit 1; }
  done
  skip="^($(printf '%s\n' "${skipped[@]}" | sed 's/\./\\./g' | paste -sd'|'))\$"
  PUSHGRAPH_TEST_SCALE=${PUSHGRAPH_TEST_SCALE:-0.25} ctest --test-dir build-sanitize -LE docs -E "$skip" \
    --output-on-failure -j"$jobs"
  exit 0
fi
# EXAMPLES explicitly: a build/ configured by quickstart.sh (tests off) cached it OFF.
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release -DPUSHGRAPH_BUILD_TESTS=ON -DPUSHGRAPH_BUILD_EXAMPLES=ON -DPUSHGRAPH_BUILD_BENCH=ON \
  -DPUSHGRAPH_BUILD_PYTHON=ON >/dev/null
cmake --build build -j"$jobs"
ctest --test-dir build --output-on-failure -j"$jobs"
bash scripts/check-install.sh build
