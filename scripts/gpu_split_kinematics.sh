#!/usr/bin/env bash
# On the GPU machine: the G2P kinematics in one launch against two (MPM_CUDA_SPLIT_KINEMATICS,
# include/mpm/core/backend/cuda_backend.h). Builds the core with the CUDA backend once, runs the
# gpu tests with the split (and the CPU-GPU agreement without it, for reference), memcheck on
# the split path, then P1 at 12.8M points and a P2-sized P1 (about 512,000 points) with per-launch
# times, one launch and two in turn, ROUNDS times. Output in $OUT.
#   scripts/gpu_split_kinematics.sh            SIZES="2560 102" ROUNDS=2 STEPS=400
set -u -o pipefail
ROOT=$(cd "$(dirname "$0")/.." && pwd)
OUT=${OUT:-$ROOT/output-gpu-split}
SIZES=${SIZES:-2560 102}
ROUNDS=${ROUNDS:-2}
STEPS=${STEPS:-400}
BUILD=${BUILD:-/tmp/build-split}
mkdir -p "$OUT"
export PATH=/usr/local/cuda/bin:$PATH
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader | tee "$OUT/machine.txt"
# One build tree per target, built side by side (a Makefile build of several targets builds
# them one after the other, and each is one long nvcc compile).
TARGETS="p1_benchmark test_gpu_cpu_agreement test_gpu_device_engine test_gpu_cpdi"
for t in $TARGETS; do
  (cmake -S "$ROOT" -B "$BUILD-$t" -DMPM_CORE_ONLY=ON -DMPM_WITH_CUDA=ON -DCMAKE_BUILD_TYPE=Release \
     -DCMAKE_CUDA_ARCHITECTURES=90 >"$OUT/build-$t.log" 2>&1 &&
   cmake --build "$BUILD-$t" --target "$t" -j 4 >>"$OUT/build-$t.log" 2>&1 || echo "build of $t failed") &
done
wait
echo "build: ok"
for t in test_gpu_cpu_agreement test_gpu_device_engine test_gpu_cpdi; do
  MPM_CUDA_SPLIT_KINEMATICS=1 "$BUILD-$t/tests/gpu/$t" >"$OUT/$t.split.log" 2>&1
  echo "$t (two launches): rc $?"
done
MPM_CUDA_SPLIT_KINEMATICS=0 "$BUILD-test_gpu_cpu_agreement/tests/gpu/test_gpu_cpu_agreement" >"$OUT/test_gpu_cpu_agreement.one.log" 2>&1
echo "test_gpu_cpu_agreement (one launch): rc $?"
if command -v compute-sanitizer >/dev/null; then
  MPM_CUDA_SPLIT_KINEMATICS=1 timeout 90 compute-sanitizer --tool memcheck "$BUILD-p1_benchmark/benchmarks/p1_benchmark" --sizes 2 --steps 20 \
    >"$OUT/memcheck.log" 2>&1
  MPM_CUDA_SPLIT_KINEMATICS=1 timeout 90 compute-sanitizer --tool memcheck "$BUILD-test_gpu_device_engine/tests/gpu/test_gpu_device_engine" >"$OUT/memcheck_engine.log" 2>&1
  echo "memcheck (two launches): $(grep -h 'ERROR SUMMARY' "$OUT"/memcheck*.log | tr '\n' ' ')"
fi
for r in $(seq "$ROUNDS"); do
  for size in $SIZES; do
    for split in 0 1; do
      echo "== round $r, size $size, split $split"
      MPM_CUDA_SPLIT_KINEMATICS=$split "$BUILD-p1_benchmark/benchmarks/p1_benchmark" --sizes "$size" --steps "$STEPS" --profile 2>&1 |
        grep -E "^\| FP|ms  " | sed 's/^/   /'
    done
  done
done 2>&1 | tee "$OUT/timings.txt"
