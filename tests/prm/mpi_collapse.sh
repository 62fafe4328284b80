#!/bin/bash
# Reduced V3 collapse (collapse_small_2d.prm) on 1, 2 and 4 MPI ranks, with a low load
# balance threshold. Asserts: final positions and stresses np-invariant to 1e-10
# (relative to the field's magnitude); on 4 ranks points migrate (counts per rank
# change, total conserved) and the grid is repartitioned by work.
# Usage: mpi_collapse.sh EXE SOURCE_DIR OUTDIR [override lines...]
set -eu
exe=$1 src=$2 out=$3 here=$(dirname "$0")
# numpy for compare_np.py: Debian's python3 (CI), else the first on PATH (GPU hosts)
py=/usr/bin/python3; "$py" -c "import numpy" 2>/dev/null || py=python3
shift 3
bash "$here/run_np.sh" "$exe" "$here/collapse_small_2d.prm" "$out" "1 2 4" \
  "subsection Parallel" "  set Load balance threshold = 1.02" "end" "$@"
"$py" "$here/compare_np.py" "$out/np1" "$out/np2" "$out/np4" --rtol 1e-10
"$py" "$here/compare_np.py" "$out/np1" "$out/np4" --rtol 1e-10 --migrated --repartitioned
