#!/usr/bin/env bash
# The one sanitizer build that `scripts/test.sh --sanitize` and scripts/fuzz.sh share: clang with
# AddressSanitizer and UndefinedBehaviorSanitizer on every library, test and the tool (not the
# examples), plus libFuzzer's coverage instrumentation (PUSHGRAPH_BUILD_FUZZERS; the libraries and
# harnesses, not the tests' own code), at -O3 with line tables (symbolized reports), in
# build-sanitize/ (SANITIZE_BUILD_DIR). Installs
# clang with its libFuzzer and sanitizer runtimes (Debian 12: clang 14) when missing. Builds the
# targets given, or everything.
#
#   bash scripts/sanitize-build.sh                      # everything
#   bash scripts/sanitize-build.sh fuzz_shape_json      # one target
set -euo pipefail
cd "$(dirname "$0")/.."
BUILD=${SANITIZE_BUILD_DIR:-build-sanitize}
bash scripts/install-deps.sh > /dev/null
missing=()
for p in clang libclang-rt-14-dev llvm-14; do
  dpkg-query -W -f='${Status}' "$p" 2> /dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  sudo_cmd=()
  [ "$(id -u)" -eq 0 ] || sudo_cmd=(sudo)
  "${sudo_cmd[@]}" apt-get update -qq
  "${sudo_cmd[@]}" env DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends "${missing[@]}" > /dev/null
fi
# Everything at the release build's -O3 with NDEBUG (an empty CMAKE_BUILD_TYPE, given here until
# 2026-11-28 to mean -O1, became Release anyway). Measured that day and not kept: the libraries at
# -O1 (the sanitized estimator tests ran 2.5 to 4 times longer), and the tests' own sources at -O0
# (their compile 88 -> 29 s a heavy file, but the sanitizer tests took 48 instead of about 25
# minutes: the tests' -O0 copies of inline templates stand in for the libraries' at link time).
CC=clang CXX=clang++ cmake -S . -B "$BUILD" -DCMAKE_BUILD_TYPE=Release -DCMAKE_CXX_FLAGS="-gline-tables-only" \
  -DPUSHGRAPH_BUILD_FUZZERS=ON -DPUSHGRAPH_BUILD_TESTS=ON -DPUSHGRAPH_BUILD_EXAMPLES=OFF -DPUSHGRAPH_BUILD_BENCH=OFF \
  -DPUSHGRAPH_BUILD_PYTHON=OFF > /dev/null
start=$(date +%s)
if [ $# -gt 0 ]; then
  cmake --build "$BUILD" -j"$(nproc)" --target "$@"
else
  cmake --build "$BUILD" -j"$(nproc)"
fi
echo "sanitize-build: built in $(( $(date +%s) - start )) s ($BUILD)"
