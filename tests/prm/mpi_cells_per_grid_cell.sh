#!/bin/bash
# Grid/Cells per deal.II cell = 4 (deal.II cells of 4 x 4 MPM cells, Q4 elements whose DoFs are
# the MPM nodes): the reduced V3 collapse with pressure averaging on 1, 2 and 4 ranks. Asserts:
# positions and stresses np-invariant to 1e-10 of the field's magnitude, points migrate and the
# grid is repartitioned on 4 ranks (as mpi_collapse.sh); on 2 ranks the particles and the grid
# files' nodal mass and velocity agree with deal.II cells of one MPM cell (k = 1) to 1e-10, the
# grid files with every cell; and the exchange holds no more ghost nodes than with k = 1 (only
# the one layer of MPM cells around a rank's cells, not the whole deal.II cells around them).
# Usage: mpi_cells_per_grid_cell.sh EXE SOURCE_DIR OUTDIR
set -eu
exe=$1 src=$2 out=$3 here=$(dirname "$0")
py=/usr/bin/python3; "$py" -c "import numpy" 2>/dev/null || py=python3
mkdir -p "$out"
scene=("subsection Parallel" "  set Load balance threshold = 1.02" "end"
       "subsection Solver" "  set Pressure averaging = true" "  set FLIP fraction = 0.99" "end")
bash "$here/run_np.sh" "$exe" "$here/collapse_small_2d.prm" "$out/k4" "1 2 4" "${scene[@]}" \
  "subsection Grid" "  set Cells per deal.II cell = 4" "end"
bash "$here/run_np.sh" "$exe" "$here/collapse_small_2d.prm" "$out/k1" "2" "${scene[@]}"
"$py" "$here/compare_np.py" "$out/k4/np1" "$out/k4/np2" "$out/k4/np4" --rtol 1e-10
"$py" "$here/compare_np.py" "$out/k4/np1" "$out/k4/np4" --rtol 1e-10 --migrated --repartitioned
"$py" "$here/compare_np.py" "$out/k1/np2" "$out/k4/np2" --rtol 1e-10
"$py" "$here/compare_grid_mass.py" "$out/k1/np2" "$out/k4/np2" --same-cells --rtol 1e-10
ghosts() { sed -n 's/.*MPI: ghost nodes \([0-9]*\) in all.*/\1/p' "$1"; }
g1=$(ghosts "$out/k1-np2.log") g4=$(ghosts "$out/k4-np2.log")
echo "ghost nodes on 2 ranks: $g4 with k = 4, $g1 with k = 1"
[ -n "$g1" ] && [ -n "$g4" ] && [ "$g4" -le "$g1" ] || { echo "FAILED: more ghost nodes with k = 4"; exit 1; }
