#!/bin/bash
# Installs what dealii-mpm needs on Debian 12 (as root) and builds it in ./build.
# Used by scripts/demo.sh and scripts/test.sh; safe to run again.
set -euo pipefail
cd "$(dirname "$0")/.."
packages="libdeal.ii-dev libfftw3-dev cmake g++ make openmpi-bin libopenmpi-dev python3-numpy python3-matplotlib python3-meshio"
missing=""
for p in $packages; do dpkg -s "$p" >/dev/null 2>&1 || missing="$missing $p"; done
if [ -n "$missing" ]; then
  echo "== installing:$missing"
  export DEBIAN_FRONTEND=noninteractive
  apt-get update -qq
  apt-get install -y -qq --no-install-recommends $missing >/dev/null
fi
echo "== building in $(pwd)/build"
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release ${MPM_CMAKE_ARGS:-} >/dev/null
cmake --build build -j "$(nproc)"
