#!/usr/bin/env bash
# On the GPU machine: where P1's step spends its time, kernel by kernel, at full size.
# Builds the P1 benchmark, times P1 (12.8M points unless SIZE says otherwise) with
# per-launch events, then reads each launch of one step's hardware counters with Nsight
# Compute: duration, DRAM bytes, how busy each unit was against its peak (DRAM, L2, L1,
# the SMs' issue), L2 reductions, local-memory (spill) traffic, occupancy, registers.
# Output in $OUT (default ./output-gpu-counters); the summary is counters.md.
#   scripts/gpu_p1_counters.sh            SIZE=2560 (12,830,720 points), EXTRA="--fp32", P1_BIN=FILE[.xz] etc.
set -u -o pipefail
ROOT=$(cd "$(dirname "$0")/.." && pwd)
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
M=gpu__time_duration.sum,dram__bytes_read.sum,dram__bytes_write.sum
M=$M,dram__throughput.avg.pct_of_peak_sustained_elapsed,lts__throughput.avg.pct_of_peak_sustained_elapsed
M=$M,l1tex__throughput.avg.pct_of_peak_sustained_elapsed,sm__throughput.avg.pct_of_peak_sustained_elapsed
M=$M,smsp__issue_active.avg.pct_of_peak_sustained_elapsed,lts__t_sectors_op_red.sum,lts__t_sectors_op_atom.sum
M=$M,lts__t_sector_hit_rate.pct,l1tex__t_sectors_pipe_lsu_mem_local_op_ld.sum,l1tex__t_sectors_pipe_lsu_mem_local_op_st.sum
M=$M,sm__warps_active.avg.pct_of_peak_sustained_active,launch__registers_per_thread
ncu --kernel-name regex:"for_each_kernel|gather_kernel_bounded|reduce_" --launch-skip "${SKIP:-2430}" --launch-count 24 --clock-control none --print-units base \
  --metrics "$M" --csv "$B" --sizes "$SIZE" --steps 320 $EXTRA >"$OUT/ncu.csv" 2>"$OUT/ncu.err" || tail -5 "$OUT/ncu.err"

python3 - "$OUT" "$SIZE" <<'PY' | tee "$OUT/counters.md"
import csv, sys, collections, re
out, size = sys.argv[1], sys.argv[2]
rows = list(csv.reader(open(f"{out}/ncu.csv")))
hdr, data, names = None, collections.OrderedDict(), {}
for r in rows:
    if r and r[0] == "ID":
        hdr = r
        continue
    if hdr is None or len(r) != len(hdr):
        continue
    d = dict(zip(hdr, r))
    data.setdefault(d["ID"], {})[d["Metric Name"]] = d["Metric Value"].replace(",", "")
    names[d["ID"]] = d["Kernel Name"]
def num(m, k):
    try:
        return float(m.get(k, "nan"))
    except ValueError:
        return float("nan")
print(f"Nsight Compute, P1 at --sizes {size}, every launch of the profiled steps (times of the launch alone)\n")
print("| # | kernel | ms | DRAM MB read / written | DRAM % | L2 % | L1 % | SM % | issue % | L2 red. sectors (M) | L2 hit % | local ld / st sectors (M) | warps active % | regs |")
print("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|")
for i, (k, m) in enumerate(data.items()):
    name = names[k]
    short = re.sub(r"\(.*", "", name).split("::")[-1].split("<")[0]
    t = num(m, "gpu__time_duration.sum")
    t_ms = t / 1e6  # ns to ms
    print(f"| {i} | {short} | {t_ms:.3f} | {num(m,'dram__bytes_read.sum')/1e6:.0f} / {num(m,'dram__bytes_write.sum')/1e6:.0f} "
          f"| {num(m,'dram__throughput.avg.pct_of_peak_sustained_elapsed'):.0f} | {num(m,'lts__throughput.avg.pct_of_peak_sustained_elapsed'):.0f} "
          f"| {num(m,'l1tex__throughput.avg.pct_of_peak_sustained_elapsed'):.0f} | {num(m,'sm__throughput.avg.pct_of_peak_sustained_elapsed'):.0f} "
          f"| {num(m,'smsp__issue_active.avg.pct_of_peak_sustained_elapsed'):.0f} | {num(m,'lts__t_sectors_op_red.sum')/1e6:.1f} "
          f"| {num(m,'lts__t_sector_hit_rate.pct'):.0f} | {num(m,'l1tex__t_sectors_pipe_lsu_mem_local_op_ld.sum')/1e6:.1f} / "
          f"{num(m,'l1tex__t_sectors_pipe_lsu_mem_local_op_st.sum')/1e6:.1f} | {num(m,'sm__warps_active.avg.pct_of_peak_sustained_active'):.0f} "
          f"| {num(m,'launch__registers_per_thread'):.0f} |")
PY
