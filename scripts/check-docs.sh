#!/usr/bin/env bash
# Runs every ```sh block of README.md and docs/*.md in a sandbox and reports file:line of each
# failing command with its stderr (the convention: docs/development.md, "Commands in the docs").
#
#   bash scripts/check-docs.sh                      # tool from build/, ../shared beside the repo
#   BUILD_DIR=build-docs bash scripts/check-docs.sh docs/cli.md
#   bash scripts/check-docs.sh --list               # print the commands, run nothing
#
# Environment: BUILD_DIR (default build; the sandbox's `build` points there), SHARED_DIR (default
# ../shared), DOCS_TIMEOUT (seconds per command, default 300). Needs the target pushgraph built.
set -euo pipefail
repo="$(cd "$(dirname "$0")/.." && pwd)"
build="${BUILD_DIR:-build}"
case "$build" in /*) ;; *) build="$repo/$build" ;; esac
exec python3 "$repo/scripts/check-docs.py" --repo "$repo" --build "$build" \
  --shared "${SHARED_DIR:-$repo/../shared}" --timeout "${DOCS_TIMEOUT:-300}" "$@"
