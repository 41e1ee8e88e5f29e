#!/usr/bin/env bash
# Installs pushgraph's build dependencies from Debian 12 packages. Idempotent: does nothing
# when everything is already there. Needs root (or sudo) only when something is missing.
set -euo pipefail
packages=(
  build-essential cmake ccache
  libcgal-dev libgmp-dev libmpfr-dev libeigen3-dev libboost-dev
  libceres-dev libsuitesparse-dev liblapack-dev
  libgtest-dev libgmock-dev libbenchmark-dev
  libtinyobjloader-dev nlohmann-json3-dev libcli11-dev libhdf5-dev
  python3  # scripts/check-docs.py, run by the docs tests
  python3-dev pybind11-dev python3-numpy python3-pytest  # the Python package (python/) and its tests
  python3-matplotlib  # examples/python/estimate_push.py draws with it
)
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -eq 0 ]; then
  echo "install-deps: all ${#packages[@]} packages present"
  exit 0
fi
echo "install-deps: installing ${missing[*]}"
sudo_cmd=()
[ "$(id -u)" -eq 0 ] || sudo_cmd=(sudo)
export DEBIAN_FRONTEND=noninteractive
"${sudo_cmd[@]}" apt-get update -qq
"${sudo_cmd[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}"
