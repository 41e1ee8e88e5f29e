#!/usr/bin/env bash
# The README's second command: build everything (libraries, tool, tests, benchmarks) and run
# every test. With --sanitize, builds every test with clang, AddressSanitizer and
# UndefinedBehaviorSanitizer in build-sanitize/ and runs them (scaled down) under them.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh
jobs=$(nproc)
if [ "${1:-}" = "--sanitize" ]; then
  # Every test (geometry, limit_surface, push, io, graph, evaluation, the tool, the examples) built
  # by clang with ASan + UBSan in build-sanitize/ (scripts/sanitize-build.sh, shared with the
  # fuzzers), iteration counts and recording subsets scaled by PUSHGRAPH_TEST_SCALE. Left out:
  # the docs tests (they run the tool's documented commands, which the main stage checks; 4 min
  # here) and two alignment tests whose pass thresholds are counts over a dozen simulated pushes
  # with noise: clang's rounding flips one borderline alignment decision (8 of 12 aligned
  # against 9 with GCC, the bound is 9), and the first takes 400 s under ASan. The same alignment
  # code runs under the sanitizers in the other Alignment and Registration tests.
  bash scripts/sanitize-build.sh
  export ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
  export LSAN_OPTIONS="suppressions=$PWD/fuzz/lsan.supp"
  # Also left out: seven tests of 88 to 150 s each under ASan (measured 2026-11-28) whose code runs
  # sanitized in shorter ones: the wedge's and finger 1's probe-radius diagnostics
  # (TwoContacts.AWedgedFingerIsEstimatedWithBothContacts, TwoFingers.BothFingersAre..., Diagnostics.*),
  # and five MIT runs of the tool (a mesh in millimetres twice more, a turned mesh, a long recording,
  # the chain solver's stopping rule), whose paths EstimateCli.AMeshInMillimetresAloneIsEstimatedAsTheRightOne,
  # the Registration tests and the ChainSolver tests run.
  skip='^(Alignment\.MisframedShapesAreAlignedAndEstimatedAsWellAsTheTrueOne|Alignment\.IncrementalModeUsesTheAlignedShape'
  skip+='|TwoContacts\.AWedgedFingerIsNotTakenForAWrongProbeRadius|TwoFingers\.AWrongRadiusOfFingerOneIsNamed'
  skip+='|EstimateCli\.(ATrueMeshOnALongRecordingIsNotMovedByTheFrameCheck|AMeshInMillimetresOnARestingPushIsOnlyItsUnits'
  skip+='|AMeshInMillimetresIsOfferedItsUnitsAlone|TheChainSolverDoesNotStopOnAMispredictedStep|AMeshTurnedBy37DegreesIsAligned))$'
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
