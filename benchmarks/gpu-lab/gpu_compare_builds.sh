#!/bin/bash
# Two builds of dealii-mpm on the same GPU machine, one run after the other (old, new), for
# before/after figures on several GPUs. Each build is a folder with dealii-mpm and its
# libdealii-mpm.so* (stripped copies are enough). On the GPU host after `. /opt/dl/dl-env.sh`:
#   gpu_compare_builds.sh OLD_DIR NEW_DIR OUTDIR PART...
# PART: p2 (benchmarks/gpu-lab/gpu_scaling.sh's P2 on 1 and 2 ranks), strong (P1 at 12.8M points on 1 and 2
# GPUs, 2000 steps), weak (P1 at 25.7M points on 2 GPUs, 2000 steps), as benchmarks/gpu-lab/gpu_two_gpu_runs.sh
# runs them. The summaries go to stdout and OUTDIR/summary.txt.
set -u -o pipefail
old=$(readlink -f "$1") new=$(readlink -f "$2") out=$3
shift 3
here=$(cd "$(dirname "$0")" && pwd)
mkdir -p "$out"
base_path=${LD_LIBRARY_PATH:-}
for part in "$@"; do
  for build in old new; do
    dir=$old
    [ $build = new ] && dir=$new
    export LD_LIBRARY_PATH=$dir:$base_path
    echo "== $part, $build build ($dir)"
    case $part in
      p2) P1_WIDTHS=" " timeout 150 bash "$here/gpu_scaling.sh" "$dir/dealii-mpm" "$out/p2_$build" 2>&1 ;;
      strong) ONE_GPU=0 END_TIME=100 timeout 200 bash "$here/gpu_rank_check.sh" "$dir/dealii-mpm" \
                "$out/strong_$build" 2053.0688 2000 2>&1 ;;
      weak) ONE_GPU=0 NP1=0 END_TIME=100 timeout 200 bash "$here/gpu_rank_check.sh" "$dir/dealii-mpm" \
              "$out/weak_$build" 4106.1376 2000 2>&1 ;;
      *) echo "unknown part $part (allowed: p2, strong, weak)" >&2; exit 2 ;;
    esac
  done
done | tee -a "$out/summary.txt"
