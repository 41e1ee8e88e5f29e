#!/usr/bin/env bash
# The docs checker itself: passes good blocks (variables and files carried, no-check and text
# blocks skipped) and fails bad ones naming file:line (a failing command with its stderr, a
# time-out, a failing pipeline, an untagged block).
# Usage: check_docs_selftest.sh REPO BUILD_DIR SHARED_DIR
set -uo pipefail
repo=$1 build=$2 shared=$3
check=(python3 "$repo/scripts/check-docs.py" --repo "$repo" --build "$build" --shared "$shared")
fixtures="$repo/tests/docs/fixtures"
status=0
fail() { echo "SELFTEST FAIL: $*"; status=1; }

out=$("${check[@]}" "$fixtures/passing.md" 2>&1); rc=$?
echo "$out"
[ $rc -eq 0 ] || fail "passing.md: exit status $rc, expected 0"
grep -q 'ok   tests/docs/fixtures/passing.md:5 (3 commands' <<<"$out" || fail "passing.md:5 not run as 3 commands"
grep -q 'skip tests/docs/fixtures/passing.md:17 (no-check: would fail' <<<"$out" || fail "no-check block not skipped"

out=$("${check[@]}" --timeout 3 "$fixtures/failing.md" 2>&1); rc=$?
echo "$out"
[ $rc -eq 1 ] || fail "failing.md: exit status $rc, expected 1"
grep -q '^tests/docs/fixtures/failing.md:5: exit status 1' <<<"$out" || fail "failing command not named at line 5"
grep -q 'no_such_shape.json' <<<"$out" || fail "the failing command's stderr is not shown"
grep -q '^tests/docs/fixtures/failing.md:10: timed out after 3 s' <<<"$out" || fail "time-out not named at line 10"
grep -q '^tests/docs/fixtures/failing.md:14: exit status 1' <<<"$out" || fail "failing pipeline not named at line 14"
grep -q '3 failed' <<<"$out" || fail "expected 3 failed blocks"

out=$("${check[@]}" "$fixtures/untagged.md" 2>&1); rc=$?
echo "$out"
[ $rc -eq 2 ] || fail "untagged.md: exit status $rc, expected 2"
grep -q 'untagged.md:3: code block without a language tag' <<<"$out" || fail "untagged block not named at line 3"
exit $status
