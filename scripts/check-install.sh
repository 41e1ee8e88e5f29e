#!/usr/bin/env bash
# Installs the build tree into a temporary prefix outside the source tree, then configures,
# builds and runs examples/consumer against it: proof that find_package(pushgraph) works.
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
echo "check-install: consumer project and installed tool passed (prefix $prefix)"
