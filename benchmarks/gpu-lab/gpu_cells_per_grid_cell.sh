#!/bin/bash
# Grid/Cells per deal.II cell with Backend = cuda, in one device call: the reduced V3 collapse with
# pressure averaging and k = 4 on 1, 2 and 4 ranks (np-invariant to 1e-10, points migrating and the
# grid repartitioned on 4), the 3D collapse with k = 2 (the same), and mpi_cuda.sh with k = 1; then P2
# to 0.01 s on 2 ranks sharing the GPU with k = 1 and k = 4 in turn (the set-up before the first
# step), and P2 whole on 1 rank with k = 1 and k = 4 in turn (the wall time).
#   . /opt/dl/dl-env.sh && BIN=DIR bash benchmarks/gpu-lab/gpu_cells_per_grid_cell.sh OUTDIR
# (DIR as for scripts/dev/gpu_prm_checks.sh.)
set -u -o pipefail
out=$1
here=$(cd "$(dirname "$0")" && pwd)
tests=$here/../../tests/prm
. "$here/../../scripts/dev/gpu_unpack_build.sh"
prepare_mpi_runs "${BIN:-build-cuda/dev}" "$out"
failed=0
cuda=("subsection Backend" "  set Backend = cuda" "end")
export MPM_VERIFY_DRIFT_BOUND=1
check collapse_2d_k4 240 bash "$tests/mpi_collapse.sh" "$exe" "$here/../.." /tmp/c2d-k4 "${cuda[@]}" \
  "subsection Solver" "  set Pressure averaging = true" "  set FLIP fraction = 0.99" "end" \
  "subsection Grid" "  set Cells per deal.II cell = 4" "end"
check collapse_3d_k2 240 bash "$tests/mpi_collapse_3d.sh" "$exe" "$here/../.." /tmp/c3d-k2 "${cuda[@]}" \
  "subsection Grid" "  set Upper corner = 0.6, 0.06, 0.12" "  set Cells per deal.II cell = 2" "end"
[ "${MPI_CUDA:-1}" = 0 ] || check mpi_cuda 360 bash "$tests/mpi_cuda.sh" "$exe" "$here/../.." /tmp/mpi_cuda
unset MPM_VERIFY_DRIFT_BOUND
p2() { # NAME NP K END_TIME: P2 with Backend = cuda
  sed -e "s|^\( *set Directory *=\).*|\1 /tmp/$1|" "$here/../../prm/granular_collapse_3d.prm" >"/tmp/$1.prm"
  printf '%s\n' "subsection Backend" "  set Backend = cuda" "end" "subsection Grid" \
    "  set Cells per deal.II cell = $3" "end" "subsection Solver" "  set End time = $4" "end" >>"/tmp/$1.prm"
  local start=$(date +%s.%N)
  if [ "$2" -gt 1 ]; then timeout 200 mpirun --bind-to none -np "$2" "$exe" "/tmp/$1.prm" >"$out/$1.log" 2>&1
  else timeout 200 "$exe" "/tmp/$1.prm" >"$out/$1.log" 2>&1; fi
  echo "== $1: rc $?, shell clock $(awk "BEGIN{print $(date +%s.%N) - $start}") s"
  grep -E "done, t =|set-up|setup: grid|setup and first|built on a thread|engine step" "$out/$1.log" | cut -c1-200
}
for round in 1 2; do
  for k in 1 4; do p2 "p2_np2_k${k}_$round" 2 $k 0.01; done
done
for round in 1 2; do
  for k in 1 4; do p2 "p2_np1_k${k}_$round" 1 $k 1; done
done
echo "== all checks: $([ $failed = 0 ] && echo passed || echo FAILED)"
exit $failed
