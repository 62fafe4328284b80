#!/bin/bash
# 3D collapse (prm/granular_collapse_3d.prm at h = 10 mm: 8,000 points, 0.1 s) with pressure
# averaging (and FLIP 0.99, as the prm) on 1, 2 and 4 MPI ranks; local damping off, because
# Cundall damping's sign(v_node) turns sum-order round-off at near-rest nodes into larger
# differences (doc/performance.md, MPI). Each rank writes 3 .vtu pieces (Output/Files per rank).
# Asserts: final positions and stresses np-invariant to 1e-10 (relative to the field's
# magnitude); on 4 ranks points migrate and the grid is repartitioned.
# Usage: mpi_collapse_3d.sh EXE SOURCE_DIR OUTDIR [override lines...]
set -eu
exe=$1 src=$2 out=$3 here=$(dirname "$0")
# numpy for compare_np.py: Debian's python3 (CI), else the first on PATH (GPU hosts)
py=/usr/bin/python3; "$py" -c "import numpy" 2>/dev/null || py=python3
shift 3
bash "$here/run_np.sh" "$exe" "$src/prm/granular_collapse_3d.prm" "$out" "1 2 4" \
  "subsection Grid" "  set Cell size = 0.01" "end" \
  "subsection Solver" "  set End time = 0.1" "  set Local damping = 0" "  set Pressure averaging = true" "end" \
  "subsection Output" "  set Output interval = 0.05" "  set Files per rank = 3" "end" \
  "subsection Parallel" "  set Load balance threshold = 1.02" "end" "$@"
"$py" "$here/compare_np.py" "$out/np1" "$out/np2" "$out/np4" --rtol 1e-10
"$py" "$here/compare_np.py" "$out/np1" "$out/np4" --rtol 1e-10 --migrated --repartitioned
