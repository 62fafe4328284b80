#!/usr/bin/env python3
"""The table of one step's launches from Nsight Compute's CSV (the metrics of ncu_step_metrics.sh):
time, DRAM bytes, each unit's share of its peak, L2 reductions, spills, occupancy, registers.
   ncu_step_table.py NCU_CSV LABEL     (benchmarks/gpu-lab/gpu_p1_counters.sh, benchmarks/gpu-lab/gpu_p2_counters.sh)"""
import csv, sys, collections, re
csv_path, label = sys.argv[1], sys.argv[2]
rows = list(csv.reader(open(csv_path)))
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
print(f"Nsight Compute, {label}, every launch of the profiled steps (times of the launch alone)\n")
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
