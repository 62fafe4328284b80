#!/usr/bin/env bash
# On the GPU machine: where the time of the CUDA step goes. Builds the P1 benchmark only,
# times P1 at 3.2M points with the points in three orders and three block sizes, runs
# 12.8M points in cell order, and reads hardware counters of the step's kernels with
# Nsight Compute (800k points). Output in $OUT (default ./output-gpu-profile).
set -u -o pipefail
ROOT=$(cd "$(dirname "$0")/../.." && pwd)
OUT=${OUT:-$ROOT/output-gpu-profile}
BUILD=${BUILD:-/tmp/build-gpu}
mkdir -p "$OUT"
export PATH=/usr/local/cuda/bin:$PATH
GEN=""
command -v ninja >/dev/null && GEN="-G Ninja"
cmake -S "$ROOT" -B "$BUILD" $GEN -DMPM_CORE_ONLY=ON -DMPM_WITH_CUDA=ON -DCMAKE_BUILD_TYPE=Release >"$OUT/build.log" 2>&1 &&
  cmake --build "$BUILD" --target p1_benchmark -j "$(nproc)" >>"$OUT/build.log" 2>&1 || { tail -30 "$OUT/build.log"; exit 1; }
B="$BUILD/benchmarks/p1_benchmark"
T="$OUT/p1_variants.md"
: >"$T"
for order in generated cell random; do
  "$B" --sizes 640 --order $order --table "$T" 2>&1 | tail -1
done
for block in 128 512; do
  "$B" --sizes 640 --block $block --table "$T" 2>&1 | tail -1
done
"$B" --sizes 2560 --order cell --profile --table "$T" 2>&1 | tail -12
"$B" --fp32 --sizes 2560 --order cell --table "$T" 2>&1 | tail -1

# Hardware counters of one step's 8 item-loop launches (after 3 warm-up steps = 24 launches)
K="--kernel-name regex:for_each_kernel --launch-skip 24 --launch-count 8 --clock-control none"
M=gpu__time_duration.sum,dram__bytes_read.sum,dram__bytes_write.sum,dram__throughput.avg.pct_of_peak_sustained_elapsed,lts__throughput.avg.pct_of_peak_sustained_elapsed,lts__t_sectors_op_red.sum,lts__t_sectors_op_atom.sum,l1tex__t_sectors_pipe_lsu_mem_local_op_ld.sum,l1tex__t_sectors_pipe_lsu_mem_local_op_st.sum,sm__warps_active.avg.pct_of_peak_sustained_active,launch__registers_per_thread,sm__throughput.avg.pct_of_peak_sustained_elapsed
for order in generated cell; do
  ncu $K --metrics $M --csv "$B" --sizes 160 --steps 1 --order $order >"$OUT/ncu_metrics_$order.csv" 2>"$OUT/ncu_metrics_$order.err" ||
    tail -5 "$OUT/ncu_metrics_$order.err"
done
ncu $K --section SpeedOfLight --section MemoryWorkloadAnalysis --section Occupancy --section LaunchStats \
  "$B" --sizes 160 --steps 1 >"$OUT/ncu_sections.txt" 2>&1 || tail -5 "$OUT/ncu_sections.txt"
python3 - "$OUT" <<'PY'
import csv, sys, collections
out = sys.argv[1]
names = ["reset grid", "P2G", "grid update", "G2P velocity", "reset momentum", "remap P2G", "nodal velocity", "G2P kinematics"]
for order in ["generated", "cell"]:
    try:
        rows = list(csv.reader(open(f"{out}/ncu_metrics_{order}.csv")))
    except OSError:
        continue
    hdr = None
    data = collections.OrderedDict()
    for r in rows:
        if r and r[0] == "ID":
            hdr = r; continue
        if hdr is None or len(r) != len(hdr):
            continue
        d = dict(zip(hdr, r))
        data.setdefault(d["ID"], {})[d["Metric Name"]] = (d["Metric Value"], d["Metric Unit"])
    print(f"ncu, 801,920 points, {order} order:")
    for i, (k, m) in enumerate(data.items()):
        g = lambda n: m.get(n, ("?", ""))
        print(f"  {names[i] if i < len(names) else k:16s} time {g('gpu__time_duration.sum')} dram rd {g('dram__bytes_read.sum')} wr {g('dram__bytes_write.sum')}"
              f" dram% {g('dram__throughput.avg.pct_of_peak_sustained_elapsed')[0]} l2% {g('lts__throughput.avg.pct_of_peak_sustained_elapsed')[0]}"
              f" red {g('lts__t_sectors_op_red.sum')[0]} atom {g('lts__t_sectors_op_atom.sum')[0]}"
              f" local ld/st {g('l1tex__t_sectors_pipe_lsu_mem_local_op_ld.sum')[0]}/{g('l1tex__t_sectors_pipe_lsu_mem_local_op_st.sum')[0]}"
              f" occ% {g('sm__warps_active.avg.pct_of_peak_sustained_active')[0]} regs {g('launch__registers_per_thread')[0]} sm% {g('sm__throughput.avg.pct_of_peak_sustained_elapsed')[0]}")
PY
echo; cat "$T"
