#!/bin/bash
# Set-up time of several ranks, two builds in turn (the grid, the points, the engine: mostly CPU work, so
# ranks may share one GPU): P2 (prm/granular_collapse_3d.prm, 100 steps, no output) on 2 ranks, ROUNDS times,
# and P1 at 25.7M points on 2 ranks (benchmarks/gpu-lab/gpu_rank_check.sh's scene, 40 steps) once. Prints the total wall
# and TimerOutput's set-up rows. On the GPU host after `. /opt/dl/dl-env.sh`:
#   gpu_setup_old_new.sh OLD_DIR NEW_DIR OUTDIR      (P1=0: without the P1 runs)
set -u -o pipefail
old=$(readlink -f "$1") new=$(readlink -f "$2") out=$3
here=$(cd "$(dirname "$0")" && pwd)
mkdir -p "$out"
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
base_path=${LD_LIBRARY_PATH:-}
prm=$out/p2_setup.prm
cp "$here/../../prm/granular_collapse_3d.prm" "$prm"
printf '%s\n' "subsection Solver" "  set Maximum number of steps = 100" "end" "subsection Output" \
  "  set Directory = $out/p2o" "  set Output interval = 0" "  set Write particles = false" \
  "  set Write grid fields = false" "  set Progress interval = 0" "end" "subsection Backend" "  set Backend = cuda" \
  "end" >>"$prm"
rows() { grep -E "Total wallclock|\| setup|\| repartition|partitioned|repartitions;" "$1" | tr -s ' ' | cut -c1-120; }
for round in $(seq "${ROUNDS:-2}"); do
  for build in old new; do
    dir=$old; [ $build = new ] && dir=$new
    export LD_LIBRARY_PATH=$dir:$base_path
    mpirun --bind-to none -np 2 "$dir/dealii-mpm" "$prm" >"$out/p2_${build}_$round.log" 2>&1
    echo "== P2 np 2, $build, round $round (rc $?)"; rows "$out/p2_${build}_$round.log"
  done
done
[ "${P1:-1}" = 1 ] && for build in old new; do
  dir=$old; [ $build = new ] && dir=$new
  export LD_LIBRARY_PATH=$dir:$base_path
  ONE_GPU=0 NP1=0 END_TIME=100 KERNEL_TIMES_FROM=1000 timeout 250 bash "$here/gpu_rank_check.sh" "$dir/dealii-mpm" \
    "$out/p1_$build" 4106.1376 40 >/dev/null 2>&1
  echo "== P1 25.7M np 2, $build"; rows "$out/p1_$build/np2.log"
done
