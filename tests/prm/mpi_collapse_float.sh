#!/bin/bash
# Reduced V3 collapse (collapse_small_2d.prm) in float (Backend/Precision) on 1, 2 and 4 MPI ranks,
# and in double on one. Asserts: positions and stresses of np 2 and np 4 differ from np 1 by no more
# than float differs from double on one rank (float's round-off on this scene; the ranks' sums only
# change its order); on 4 ranks points migrate and the grid is repartitioned by work. Override
# lines (e.g. Backend = cuda) apply to every run, the double one included.
# Usage: mpi_collapse_float.sh EXE OUTDIR [override lines...]
set -eu
exe=$1 out=$2 here=$(dirname "$0")
shift 2
py=/usr/bin/python3; "$py" -c "import numpy" 2>/dev/null || py=python3
mkdir -p "$out"
balance=("subsection Parallel" "  set Load balance threshold = 1.02" "end")
bash "$here/run_np.sh" "$exe" "$here/collapse_small_2d.prm" "$out/float" "1 2 4" "${balance[@]}" \
  "$@" "subsection Backend" "  set Precision = float" "end"
grep -Eq "backend (cpu|cuda) in float" "$out/float-np2.log" || { echo "FAILED: the np 2 run was not in float"; exit 1; }
bash "$here/run_np.sh" "$exe" "$here/collapse_small_2d.prm" "$out/double" "1" "${balance[@]}" "$@"
"$py" "$here/compare_np.py" "$out/float/np1" "$out/float/np2" "$out/float/np4" --spread "$out/double/np1" \
  --spread-factor 1 --rtol 0
"$py" "$here/compare_np.py" "$out/float/np1" "$out/float/np4" --spread "$out/double/np1" --spread-factor 1 \
  --rtol 0 --migrated --repartitioned
