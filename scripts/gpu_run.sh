#!/usr/bin/env bash
# On the GPU machine (CUDA, CMake, python3; no deal.II): configure the compute core with the
# CUDA backend, build, run the core and gpu ctest labels, compute-sanitizer on a small scene,
# and the P1 benchmark; everything goes to $OUT (default ./output-gpu), the benchmark table
# to $OUT/p1_table.md. Run from the repository root:
#   scripts/gpu_run.sh [quick]      quick: benchmark sizes up to 3.2M points only
# The whole build does not fit one call of the device tool (10 minutes): on an H100 with nvcc 13.0
# three calls of 10, 10 and 8 minutes ended still linking the GPU tests (doc/log.md, 2026-12-05).
# Within one call, build the test programs on the development VM and carry them over
# (benchmarks/gpu-lab/gpu_fused_step.sh shows how), or build one target at a time here.
set -u -o pipefail
ROOT=$(cd "$(dirname "$0")/.." && pwd)
OUT=${OUT:-$ROOT/output-gpu}
BUILD=${BUILD:-/tmp/build-gpu}
MODE=${1:-full}
mkdir -p "$OUT"
export PATH=/usr/local/cuda/bin:$PATH
status=0

{
  date -u +"%Y-%m-%d %H:%M UTC"
  nvidia-smi --query-gpu=name,driver_version,memory.total,clocks.max.sm,clocks.max.mem --format=csv
  nvcc --version | tail -2
  cmake --version | head -1
} 2>&1 | tee "$OUT/machine.txt"

GEN=""
command -v ninja >/dev/null && GEN="-G Ninja"
cmake -S "$ROOT" -B "$BUILD" $GEN -DMPM_CORE_ONLY=ON -DMPM_WITH_CUDA=ON -DCMAKE_BUILD_TYPE=Release \
  >"$OUT/build.log" 2>&1 || { tail -30 "$OUT/build.log"; exit 1; }
cmake --build "$BUILD" -j "$(nproc)" >>"$OUT/build.log" 2>&1 || { tail -40 "$OUT/build.log"; exit 1; }
echo "build: ok"

# -V keeps every test's own output (prefixed by the test number) in the log
(cd "$BUILD" && ctest -L "core|gpu" -V -j 4 2>&1) >"$OUT/ctest.log" || status=1
grep -E "tests passed|tests failed|Skipped|Failed|\*\*\*" "$OUT/ctest.log" | tail -12
grep -E "GPU-CPU|GPU .*(rigid|free|P2G|max)|^[0-9]+: +(16|32|64) " "$OUT/ctest.log" | head -60

B="$BUILD/benchmarks/p1_benchmark"
if command -v compute-sanitizer >/dev/null; then
  # small scene: P1 with 2 cells across (10,024 points), 20 steps
  compute-sanitizer --tool memcheck --leak-check full "$B" --sizes 2 --steps 20 >"$OUT/memcheck.log" 2>&1 || status=1
  compute-sanitizer --tool racecheck "$B" --sizes 2 --steps 5 >"$OUT/racecheck.log" 2>&1 || status=1
  # the device engine (dealii-mpm's Backend = cuda) with pressure averaging: its scatter in
  # the kinematics and its gather deferred to the next P2G
  compute-sanitizer --tool memcheck "$BUILD/tests/gpu/test_gpu_device_engine" >"$OUT/memcheck_engine.log" 2>&1 || status=1
  # the other scatters (2D, linear; MUSL, USL, USF) in the short form racecheck finishes (30 s
  # on an H100; the whole test does not end in minutes), and the device engine (190 s)
  compute-sanitizer --tool racecheck "$BUILD/tests/gpu/test_gpu_transfer_conservation" --short \
    >"$OUT/racecheck_transfer.log" 2>&1 || status=1
  compute-sanitizer --tool racecheck "$BUILD/tests/gpu/test_gpu_device_engine" >"$OUT/racecheck_engine.log" 2>&1 || status=1
  echo "memcheck:  $(grep -E 'ERROR SUMMARY|LEAK SUMMARY' "$OUT/memcheck.log" | tr '\n' ' ')"
  echo "memcheck (device engine): $(grep -E 'ERROR SUMMARY' "$OUT/memcheck_engine.log" | tr '\n' ' ')"
  echo "racecheck: $(grep -E 'RACECHECK SUMMARY|ERROR SUMMARY' "$OUT/racecheck.log" | tr '\n' ' ')"
  echo "racecheck (transfers, short): $(grep -E 'RACECHECK SUMMARY|ERROR SUMMARY' "$OUT/racecheck_transfer.log" | tr '\n' ' ')"
  echo "racecheck (device engine): $(grep -E 'RACECHECK SUMMARY|ERROR SUMMARY' "$OUT/racecheck_engine.log" | tr '\n' ' ')"
else
  echo "compute-sanitizer: not found"
fi

T="$OUT/p1_table.md"
{
  echo "P1 (elastic phase, ep2-3De's Drucker-Prager with plasticity on, unless the row says elastic), CUDA backend, $(head -1 "$OUT/machine.txt")"
  echo
  echo "| prec | points | cells | steps | wall s | point-updates/s | ms/step | min bytes/point/step | fraction of copy BW | MTP_eff GB/s |"
  echo "|---|---|---|---|---|---|---|---|---|---|"
} >"$T"
if [ "$MODE" = quick ]; then
  "$B" --sizes 20,160,640 --profile --table "$T" 2>&1 | tee "$OUT/bench.log" || status=1
else
  "$B" --sizes 20,160,640,2560 --profile --table "$T" 2>&1 | tee "$OUT/bench.log" || status=1
  "$B" --fp32 --sizes 20,2560 --profile --table "$T" 2>&1 | tee -a "$OUT/bench.log" || status=1
  # one change at a time against the default: no sorting, the linear elastic stand-in
  "$B" --sizes 2560 --sort-every 0 --table "$T" 2>&1 | tee -a "$OUT/bench.log" || status=1
  "$B" --sizes 2560 --material elastic --table "$T" 2>&1 | tee -a "$OUT/bench.log" || status=1
  # larger than the published sizes, a fixed number of steps
  "$B" --sizes 10240 --steps 60 --table "$T" 2>&1 | tee -a "$OUT/bench.log" || status=1
fi
echo
cat "$T"
exit $status
