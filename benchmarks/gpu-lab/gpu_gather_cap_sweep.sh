#!/usr/bin/env bash
# On the GPU machine: the gather kernels' register cap (MPM_GATHER_MIN_BLOCKS, resident
# blocks of 128 threads per SM) against the time of the G2P launches. Builds p1_benchmark
# once per cap (in parallel), then runs P1 (12.8M points) and a P2-sized P1 (about 512,000
# points) with per-launch times, the builds in turn, ROUNDS times. Output in $OUT.
#   benchmarks/gpu-lab/gpu_gather_cap_sweep.sh            CAPS="4 5 6 8" SIZES="2560 102" ROUNDS=2
set -u -o pipefail
ROOT=$(cd "$(dirname "$0")/../.." && pwd)
OUT=${OUT:-$ROOT/output-gpu-caps}
CAPS=${CAPS:-4 5 6 8}
SIZES=${SIZES:-2560 102}
ROUNDS=${ROUNDS:-2}
STEPS=${STEPS:-400}
mkdir -p "$OUT"
export PATH=/usr/local/cuda/bin:$PATH
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader | tee "$OUT/machine.txt"
jobs_per_build=$(( $(nproc) / $(echo $CAPS | wc -w) ))
for cap in $CAPS; do
  (cmake -S "$ROOT" -B /tmp/build-cap$cap -DMPM_CORE_ONLY=ON -DMPM_WITH_CUDA=ON -DCMAKE_BUILD_TYPE=Release \
     -DCMAKE_CUDA_ARCHITECTURES=90 -DCMAKE_CUDA_FLAGS="-DMPM_GATHER_MIN_BLOCKS=$cap -Xptxas -warn-spills" \
     >"$OUT/build$cap.log" 2>&1 &&
   cmake --build /tmp/build-cap$cap --target p1_benchmark -j "$jobs_per_build" >>"$OUT/build$cap.log" 2>&1 ||
   echo "build $cap failed") &
done
wait
for r in $(seq "$ROUNDS"); do
  for size in $SIZES; do
    for cap in $CAPS; do
      echo "== round $r, size $size, cap $cap"
      /tmp/build-cap$cap/benchmarks/p1_benchmark --sizes "$size" --steps "$STEPS" --profile 2>&1 |
        grep -E "^\| FP|ms  " | sed 's/^/   /'
    done
  done
done 2>&1 | tee "$OUT/sweep.txt"
