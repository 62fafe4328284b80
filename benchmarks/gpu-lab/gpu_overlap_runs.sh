#!/bin/bash
# The exchange's overlap on several GPUs, on and off in one build, in turn (doc/performance.md,
# "Several GPUs"): each PART runs with the overlap (default) and with MPM_CUDA_OVERLAP=0, REPEAT
# times (default 1), alternating. PART: p2 (P2 end to end on 1 and 2 ranks), strong (P1 at 12.8M
# points on 2 GPUs, 2000 steps), weak (P1 at 25.7M points on 2 GPUs, 2000 steps), as
# benchmarks/gpu-lab/gpu_two_gpu_runs.sh runs them. On the GPU host after `. /opt/dl/dl-env.sh`:
#   gpu_overlap_runs.sh BUILD_DIR OUTDIR PART...
set -u -o pipefail
dir=$(readlink -f "$1") out=$2
shift 2
here=$(cd "$(dirname "$0")" && pwd)
mkdir -p "$out"
export LD_LIBRARY_PATH=$dir:${LD_LIBRARY_PATH:-}
for part in "$@"; do
  for round in $(seq "${REPEAT:-1}"); do
    for overlap in 1 0; do
      export MPM_CUDA_OVERLAP=$overlap
      name=${part}_overlap${overlap}_$round
      echo "== $part, overlap $overlap, round $round"
      case $part in
        p2) P1_WIDTHS=" " timeout 150 bash "$here/gpu_scaling.sh" "$dir/dealii-mpm" "$out/$name" 2>&1 ;;
        strong) ONE_GPU=0 NP1=0 END_TIME=100 timeout 200 bash "$here/gpu_rank_check.sh" "$dir/dealii-mpm" \
                  "$out/$name" 2053.0688 2000 2>&1 ;;
        weak) ONE_GPU=0 NP1=0 END_TIME=100 timeout 240 bash "$here/gpu_rank_check.sh" "$dir/dealii-mpm" \
                "$out/$name" 4106.1376 2000 2>&1 ;;
        *) echo "unknown part $part (allowed: p2, strong, weak)" >&2; exit 2 ;;
      esac
    done
  done
done | tee -a "$out/summary.txt"
