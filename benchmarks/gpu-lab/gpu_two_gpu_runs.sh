#!/bin/bash
# Issue 18's runs on a machine with two GPUs, in one device call (about 6 minutes on 2x H200):
#   1. agreement: tests/prm/mpi_cuda.sh (np 1, 2, 4 against np 1; cuda against cpu);
#   2. P2 end to end on 1 and 2 ranks (benchmarks/gpu-lab/gpu_scaling.sh);
#   3. P1 at 12.8M points, 2000 steps: 1 GPU and 2 GPUs (strong), then 25.7M points on 2 GPUs (weak), with
#      per-rank kernel times, the exchange's device time and the re-sorts (benchmarks/gpu-lab/gpu_rank_check.sh).
# The one-rank P1 run needs its 2000 steps: on one rank the steps start beside deal.II's grid build, which
# takes about 16 s at this size (doc/performance.md, "Several GPUs").
# On the GPU host after `. /opt/dl/dl-env.sh`:   gpu_two_gpu_runs.sh EXE OUTDIR   (AGREEMENT=0: without step 1)
set -u -o pipefail
exe=$(readlink -f "$1") out=$2
here=$(cd "$(dirname "$0")" && pwd)
mkdir -p "$out"
nvidia-smi --query-gpu=name,driver_version,memory.total --format=csv,noheader

if [ "${AGREEMENT:-1}" = 1 ]; then
  timeout 240 bash "$here/../../tests/prm/mpi_cuda.sh" "$exe" "$here/../.." "$out/mpi_cuda" >"$out/mpi_cuda.log" 2>&1
  echo "== agreement (tests/prm/mpi_cuda.sh): rc $?"
  grep "largest difference" "$out/mpi_cuda.log" | sort -u
fi

echo "== P2"
P1_WIDTHS=" " timeout 150 bash "$here/gpu_scaling.sh" "$exe" "$out/p2" 2>&1

echo "== P1 strong (12,830,720 points)"
ONE_GPU=0 END_TIME=100 timeout 200 bash "$here/gpu_rank_check.sh" "$exe" "$out/p1_strong" 2053.0688 2000 2>&1
echo "== P1 weak (25,661,440 points on 2 GPUs)"
ONE_GPU=0 NP1=0 END_TIME=100 timeout 200 bash "$here/gpu_rank_check.sh" "$exe" "$out/p1_weak" 4106.1376 2000 2>&1
