#!/usr/bin/env bash
# On the GPU machine: where P1's step spends its time, kernel by kernel, at full size.
# Builds the P1 benchmark, times P1 (12.8M points unless SIZE says otherwise) with
# per-launch events, then reads each launch of one step's hardware counters with Nsight
# Compute: duration, DRAM bytes, how busy each unit was against its peak (DRAM, L2, L1,
# the SMs' issue), L2 reductions, local-memory (spill) traffic, occupancy, registers.
# Output in $OUT (default ./output-gpu-counters); the summary is counters.md.
#   benchmarks/gpu-lab/gpu_p1_counters.sh            SIZE=2560 (12,830,720 points), EXTRA="--fp32", P1_BIN=FILE[.xz] etc.
set -u -o pipefail
ROOT=$(cd "$(dirname "$0")/../.." && pwd)
OUT=${OUT:-$ROOT/output-gpu-counters}
BUILD=${BUILD:-/tmp/build-counters}
SIZE=${SIZE:-2560}
EXTRA=${EXTRA:-}
mkdir -p "$OUT"
export PATH=/usr/local/cuda/bin:$PATH
nvidia-smi --query-gpu=name,driver_version,clocks.max.sm,clocks.max.mem --format=csv,noheader | tee "$OUT/machine.txt"
# P1_BIN: a p1_benchmark built elsewhere (the build takes minutes of device time), or its .xz.
if [ -n "${P1_BIN:-}" ]; then
  B=$P1_BIN
  case $B in *.xz) python3 -c "import lzma,shutil,sys; shutil.copyfileobj(lzma.open(sys.argv[1]), open(sys.argv[2],'wb'))" "$B" /tmp/p1_benchmark &&
    chmod +x /tmp/p1_benchmark && B=/tmp/p1_benchmark ;; esac
else
  cmake -S "$ROOT" -B "$BUILD" -DMPM_CORE_ONLY=ON -DMPM_WITH_CUDA=ON -DCMAKE_BUILD_TYPE=Release \
    -DCMAKE_CUDA_ARCHITECTURES=90 >"$OUT/build.log" 2>&1 &&
    cmake --build "$BUILD" --target p1_benchmark -j "$(nproc)" >>"$OUT/build.log" 2>&1 || { tail -30 "$OUT/build.log"; exit 1; }
  B="$BUILD/benchmarks/p1_benchmark"
fi

# Timed run (the benchmark also measures the device-to-device copy bandwidth).
[ "${TIMED:-1}" = 1 ] &&
  "$B" --sizes "$SIZE" --steps 400 --profile $EXTRA 2>&1 | tee "$OUT/p1_timed.txt" | grep -E "device:|^\| |per-launch|^    "

# Counters of 24 launches from the SKIP-th on (8 launches per step, 2 more per re-sort: the
# default 2430 lands near step 300). Not the first steps: there the points sit where GIMP's
# weights vanish exactly at many nodes, whose atomics the scatters skip. Each launch is
# replayed once per group of counters, so the times are those of the launch alone.
. "$ROOT/benchmarks/gpu-lab/ncu_step_metrics.sh"
ncu --kernel-name regex:"for_each_kernel|gather_kernel_bounded|reduce_" --launch-skip "${SKIP:-2430}" --launch-count 24 --clock-control none --print-units base \
  --metrics "$NCU_STEP_METRICS" --csv "$B" --sizes "$SIZE" --steps 320 $EXTRA >"$OUT/ncu.csv" 2>"$OUT/ncu.err" || tail -5 "$OUT/ncu.err"

python3 "$ROOT/benchmarks/gpu-lab/ncu_step_table.py" "$OUT/ncu.csv" "P1 at --sizes $SIZE" | tee "$OUT/counters.md"
