#!/usr/bin/env bash
# On the GPU machine: the core's GPU tests and the P1 benchmark's rows per shape function
# (12.8M points, 400 steps), and the default path (GIMP det F, Drucker-Prager,
# Jaumann) timed against an older tree's build, interleaved. Everything goes to $OUT.
#   benchmarks/gpu-lab/gpu_shape_rows.sh [OLD_TREE]      OLD_TREE: a checkout of the earlier commit
#   ROWS=0: only the default against the old tree; ROWS=physics: TPIC, APIC and Hencky beside
#   their standard rows; ROWS=cpdi: CPDI (blend, TPIC) beside cpGIMP U; ROWS=old: linear,
#   uGIMP and the quadratic B-spline against the old tree too, in turn. TESTS=0: no tests;
#   TESTS="a b": those tests (each GPU test is a long device compile: four tests and both trees
#   took 509 s on an H200 host)
set -u -o pipefail
ROOT=$(cd "$(dirname "$0")/../.." && pwd)
OUT=${OUT:-$ROOT/output-gpu}
OLD=${1:-}
mkdir -p "$OUT"
export PATH=/usr/local/cuda/bin:$PATH
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader | tee "$OUT/machine.txt"
build() { # source build-dir targets...
  local src=$1 dir=$2; shift 2
  cmake -S "$src" -B "$dir" -DMPM_CORE_ONLY=ON -DMPM_WITH_CUDA=ON -DCMAKE_BUILD_TYPE=Release \
    -DCMAKE_CUDA_ARCHITECTURES=90 >"$dir.log" 2>&1 && cmake --build "$dir" -j "$(nproc)" --target "$@" >>"$dir.log" 2>&1
}
T0=$(date +%s)
TESTS=${TESTS:-test_gpu_elastic_column test_gpu_physics test_gpu_cpu_agreement}
[ "$TESTS" = 0 ] && TESTS=""
targets="p1_benchmark $TESTS"
build "$ROOT" /tmp/new $targets || { tail -30 /tmp/new.log; exit 1; } &
if [ -n "$OLD" ]; then build "$OLD" /tmp/old p1_benchmark || { tail -30 /tmp/old.log; exit 1; } & fi
wait
echo "builds: $(( $(date +%s) - T0 )) s"
for t in $TESTS; do
  timeout 300 /tmp/new/tests/gpu/$t >"$OUT/$t.log" 2>&1; echo "$t: exit $?"
  grep -E "GPU-CPU|FAILED|passed|cubic|quadratic|^ +(16|32|64) " "$OUT/$t.log" | head -40
done
P="--sizes 2560 --steps 400"
row() { echo "== $* ($(date +%T))"; timeout 150 "$@" $P 2>&1 | grep -E "^\| " | tail -1; }
{
  if [ -n "$OLD" ]; then
    for round in 1 2; do
      row /tmp/old/benchmarks/p1_benchmark
      row /tmp/new/benchmarks/p1_benchmark
    done
  fi
  if [ "${ROWS:-1}" = old ] && [ -n "$OLD" ]; then # the other stencil widths, old and new in turn
    for shape in "--shape linear" "--domain none" "--shape bspline2"; do
      row /tmp/old/benchmarks/p1_benchmark $shape
      row /tmp/new/benchmarks/p1_benchmark $shape
    done
  fi
  if [ "${ROWS:-1}" = physics ]; then # the affine transfers and Hencky (DevicePhysics::all) beside the standard rows
    row /tmp/new/benchmarks/p1_benchmark --domain none
    row /tmp/new/benchmarks/p1_benchmark --domain none --transfer tpic
    row /tmp/new/benchmarks/p1_benchmark --shape bspline2
    row /tmp/new/benchmarks/p1_benchmark --shape bspline2 --transfer apic
    row /tmp/new/benchmarks/p1_benchmark --law hencky
    row /tmp/new/benchmarks/p1_benchmark --domain U --law hencky
  fi
  if [ "${ROWS:-1}" = cpdi ]; then # with an old tree, its CPDI rows first
    row /tmp/new/benchmarks/p1_benchmark --domain U
    for tree in ${OLD:+/tmp/old} /tmp/new; do
      row $tree/benchmarks/p1_benchmark --shape cpdi
      row $tree/benchmarks/p1_benchmark --shape cpdi --transfer tpic
    done
  fi
  if [ "${ROWS:-1}" = 1 ]; then
    row /tmp/new/benchmarks/p1_benchmark --shape linear
    row /tmp/new/benchmarks/p1_benchmark --domain none
    row /tmp/new/benchmarks/p1_benchmark --shape bspline2
    row /tmp/new/benchmarks/p1_benchmark --shape bspline3
    row /tmp/new/benchmarks/p1_benchmark --domain U
  fi
} 2>&1 | tee "$OUT/p1_rows.log"
