#!/bin/bash
# The reduced collapse (tests/prm/collapse_small_2d.prm to 2 s, pure FLIP, no-slip base) on one rank with
# Backend = cuda (double, float) and cpu (double) on the same machine: kinetic energy over time and the fastest
# point per output (benchmarks/gpu-lab/float_runaway_where.py). Points near the floor keep FLIP velocities (up to 0.77 m/s)
# they do not move with, 0.035 J at 2 s, on either backend (doc/methods.md, "Pure FLIP at a no-slip base").
#   . /opt/dl/dl-env.sh && BIN=build-cuda/dev bash benchmarks/gpu-lab/gpu_flip_floor.sh OUTDIR
set -u -o pipefail
out=$1
here=$(cd "$(dirname "$0")" && pwd)
. "$here/../../scripts/dev/gpu_unpack_build.sh"
prepare_mpi_runs "${BIN:-build-cuda/dev}" "$out"
work=${WORK:-/tmp/flip-floor}
mkdir -p "$work"
eval "$(sed -n '/^scene()/,/^}/p' "$here/gpu_float_runaway.sh")"
for case in ${CASES:-cuda-double cuda-float cpu-double}; do
  backend=${case%-*} precision=${case#*-}
  scene "$work/$case" 0 1 | sed -e "s/set Precision = float/set Precision = $precision/" \
    -e "s/set Backend = cuda/set Backend = $backend/" > "$work/$case.prm"
  start=$(date +%s%N)
  "$exe" "$work/$case.prm" > "$work/$case.log" 2>&1
  echo "$case: rc $?, $(( ($(date +%s%N) - start) / 1000000 )) ms; time, dt, step, kinetic energy:"
  awk -F, 'NR > 1 && NR % 400 == 2 { print "  " $1, $2, $3, $4 }' "$work/$case/history.csv"
  tail -1 "$work/$case/history.csv" | awk -F, '{ print "  " $1, $2, $3, $4 }'
  python3 "$here/float_runaway_where.py" "$work/$case" 0.05 0.3 4
done
