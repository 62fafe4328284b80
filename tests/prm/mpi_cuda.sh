#!/bin/bash
# Backend = cuda on 1, 2 and 4 MPI ranks (one GPU per rank; ranks beyond a node's GPUs
# share them). The scenes and assertions of the CPU's MPI tests: the reduced 2D V3 collapse
# (mpi_collapse.sh; also with APIC, the quadratic B-spline and Hencky's law, and that on 1 rank
# against the CPU) and the 3D collapse with pressure averaging (mpi_collapse_3d.sh), final
# positions and stresses np-invariant to 1e-10 of the field's magnitude, points migrating
# and the grid repartitioned on 4 ranks. Then the 3D scene on 2 ranks, cuda against cpu,
# per point to the same 1e-10 (no local damping: round-off stays round-off). And the 2D collapse
# in float (Backend/Precision) on 1, 2 and 4 ranks, with and without pressure averaging, bounded
# as the CPU's float test (mpi_collapse_float.sh).
# Every step also checks the home-cell bound (MPM_VERIFY_DRIFT_BOUND).
# Exits 77 (ctest: skipped) where no CUDA device is found.
# Usage: mpi_cuda.sh EXE SOURCE_DIR OUTDIR
set -eu
exe=$1 src=$2 out=$3 here=$(dirname "$0")
# numpy for compare_np.py: Debian's python3 (CI), else the first on PATH (GPU hosts)
py=/usr/bin/python3; "$py" -c "import numpy" 2>/dev/null || py=python3
if ! nvidia-smi -L >/dev/null 2>&1; then
  echo "no CUDA device: skipped"
  exit 77
fi
mkdir -p "$out"
# Every step checks the points against the bound that lets the runs skip most checks (as the CPU's).
export MPM_VERIFY_DRIFT_BOUND=1
cuda=("subsection Backend" "  set Backend = cuda" "end")
echo "== 2D collapse, cuda, 1 2 4 ranks"
bash "$here/mpi_collapse.sh" "$exe" "$src" "$out/collapse-2d" "${cuda[@]}"
echo "== 2D collapse with APIC on the quadratic B-spline and Hencky's law, cuda, 1 2 4 ranks"
# The step's second variant of kernels (DevicePhysics::all); the affine matrices migrate with the points.
affine=("subsection Solver" "  set Shape function = quadratic B-spline" "  set Velocity transfer = APIC" "end"
        "subsection Material aluminium bars" "  set Elastic law = Hencky" "end")
bash "$here/mpi_collapse.sh" "$exe" "$src" "$out/collapse-2d-affine" "${affine[@]}" "${cuda[@]}"
echo "== the same on 1 rank: cpu against cuda"
bash "$here/run_np.sh" "$exe" "$here/collapse_small_2d.prm" "$out/collapse-2d-affine-cpu" "1" \
  "subsection Parallel" "  set Load balance threshold = 1.02" "end" "${affine[@]}"
"$py" "$here/compare_np.py" "$out/collapse-2d-affine-cpu/np1" "$out/collapse-2d-affine/np1" --rtol 1e-10
echo "== 2D collapse in float, cuda, 1 2 4 ranks (bound: float against double on 1 rank)"
bash "$here/mpi_collapse_float.sh" "$exe" "$out/collapse-2d-float" "${cuda[@]}"
echo "== the same with pressure averaging (its cell sums exchanged in float too)"
bash "$here/mpi_collapse_float.sh" "$exe" "$out/collapse-2d-float-averaging" "${cuda[@]}" \
  "subsection Solver" "  set Pressure averaging = true" "end"
echo "== 3D collapse with pressure averaging, cuda, 1 2 4 ranks"
bash "$here/mpi_collapse_3d.sh" "$exe" "$src" "$out/collapse-3d" "${cuda[@]}"
echo "== 3D collapse on 2 ranks: cpu against cuda"
bash "$here/run_np.sh" "$exe" "$src/prm/granular_collapse_3d.prm" "$out/collapse-3d-cpu" "2" \
  "subsection Grid" "  set Cell size = 0.01" "end" \
  "subsection Solver" "  set End time = 0.1" "  set Local damping = 0" "  set Pressure averaging = true" "end" \
  "subsection Output" "  set Output interval = 0.05" "  set Files per rank = 3" "end" \
  "subsection Parallel" "  set Load balance threshold = 1.02" "end"
"$py" "$here/compare_np.py" "$out/collapse-3d-cpu/np2" "$out/collapse-3d/np2" --rtol 1e-10
