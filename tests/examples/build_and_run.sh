#!/bin/bash
# Installs the build tree's dealii-mpm into a fresh prefix, configures an example as a separate
# CMake project that finds the installed package (find_package(dealii-mpm)), builds it and runs it
# there. Usage: build_and_run.sh BUILD_DIR EXAMPLE_DIR WORK_DIR
set -euo pipefail
build=$1 example=$2 work=$3
name=$(basename "$example")
rm -rf "$work" && mkdir -p "$work"
cmake --install "$build" --prefix "$work/prefix" >"$work/install.log"
# The example sees the installed package only, not the build tree.
cmake -S "$example" -B "$work/build" -DCMAKE_BUILD_TYPE=Release -DCMAKE_PREFIX_PATH="$work/prefix" \
  >"$work/configure.log" || { cat "$work/configure.log"; exit 1; }
cmake --build "$work/build" -j 2 >"$work/build.log" || { tail -40 "$work/build.log"; exit 1; }
if ldd "$work/build/$name" | grep -q "$build/libdealii-mpm"; then
  echo "FAILED: $name links the build tree's library, not the installed one"; exit 1
fi
cd "$work" && "$work/build/$name"
