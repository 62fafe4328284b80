#!/bin/bash
# Backend = cuda on several ranks (ranks sharing the one GPU where only one is lent), in one device call:
#   1. tests/prm/mpi_cuda.sh (ctest gpu/mpi_cuda_np124): double np 1, 2, 4 and cuda against cpu, then the
#      2D collapse in float on 1, 2, 4 ranks, with and without pressure averaging;
#   2. kill and resume (tests/prm/checkpoint_kill.sh): float on 2 ranks resumed on 2, double 2 resumed on 1.
# On the GPU host, from the repository root:
#   . /opt/dl/dl-env.sh && BIN=build-cuda/dev bash benchmarks/gpu-lab/gpu_float_ranks.sh OUTDIR
set -u -o pipefail
out=$1
here=$(cd "$(dirname "$0")" && pwd)
. "$here/../../scripts/dev/gpu_unpack_build.sh"
prepare_mpi_runs "${BIN:-build-cuda/dev}" "$out"
start=$(date +%s)
timeout 360 bash "$here/../../tests/prm/mpi_cuda.sh" "$exe" "$here/../.." "$out/mpi_cuda" >"$out/mpi_cuda.log" 2>&1
echo "== tests/prm/mpi_cuda.sh: rc $? ($(($(date +%s) - start)) s)"
grep -E "^==|largest|FAILED|migrated|repartition" "$out/mpi_cuda.log" | cut -c1-300
for case in "2 2 float" "2 1 double"; do
  set -- $case
  start=$(date +%s)
  timeout 150 bash "$here/../../tests/prm/checkpoint_kill.sh" "$exe" "/tmp/checkpoint-$1-$2-$3" "$1" "$2" KILL cuda all "$3" \
    >"$out/checkpoint-$1-$2-$3.log" 2>&1
  echo "== checkpoint_kill.sh np $1 resumed on $2, $3: rc $? ($(($(date +%s) - start)) s)"
  tail -4 "$out/checkpoint-$1-$2-$3.log" | cut -c1-300
done
