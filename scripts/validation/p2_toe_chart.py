#!/usr/bin/python3
"""The chart of P2's deposit toe against the method (issue 15): one bar per variant of
doc/p2_toe.csv (written from benchmarks/gpu-lab/p2_deposit_variants.sh runs), the experiment's 0.42-0.45 m
shaded, ep2-3De's 0.441 m on the same scene marked, the top-left height written on each bar.

Usage: p2_toe_chart.py [CSV] [PNG]   (default doc/p2_toe.csv, doc/figures/p2_toe.png)
"""
import csv
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

root = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..")
source = sys.argv[1] if len(sys.argv) > 1 else os.path.join(root, "doc", "p2_toe.csv")
target = sys.argv[2] if len(sys.argv) > 2 else os.path.join(root, "doc", "figures", "p2_toe.png")
rows = list(csv.DictReader(open(source)))

fig, ax = plt.subplots(figsize=(9, 0.42 * len(rows) + 1.4))
ax.axvspan(0.42, 0.45, color="tab:green", alpha=0.2, label="experiment (Bui et al. 2008), 0.42-0.45 m")
ax.axvline(0.441, color="tab:purple", linestyle="--", label="ep2-3De on the same scene, 0.441 m")
for k, r in enumerate(rows):
    y = len(rows) - 1 - k
    if not r["toe_m"]:
        ax.text(0.36, y, "unstable", va="center", color="tab:red")
        continue
    toe = float(r["toe_m"])
    inside = 0.42 <= toe <= 0.45 and abs(float(r["top_left_m"]) - 0.099) <= 0.002
    ax.barh(y, toe - 0.35, left=0.35, color="tab:blue" if inside else "tab:gray")
    ax.text(min(toe, 0.595) + 0.002, y, f"{toe:.3f} m, top-left {float(r['top_left_m']):.4f} m, {r['wall_s']} s",
            va="center", fontsize=7)
ax.set_yticks(range(len(rows)))
# Rows from another machine than the first row's are marked with it (timings compare within one machine).
def label(r):
    return r["variant"] + ("" if r["machine"] == rows[0]["machine"] else " (" + r["machine"].split("(")[0].strip() + ")")
ax.set_yticklabels([label(r) for r in reversed(rows)], fontsize=8)
ax.set_xlim(0.35, 0.68)
ax.set_xlabel("toe: 99.9th percentile of x at t = 1 s (m)")
marked = [r for r in rows if r["machine"] != rows[0]["machine"]]
dates = sorted({r["date"] for r in marked})
ax.set_title(f"P2, 512,000 points, Backend = cuda: the toe against the method\n({rows[0]['machine']}, {rows[0]['date']}"
             + (f"; marked rows: {marked[-1]['machine'].split('(')[0].strip()}, {', '.join(dates)})" if marked else ")"),
             fontsize=9)
ax.legend(loc="lower right", fontsize=7)
fig.tight_layout()
fig.savefig(target, dpi=110)
print(f"wrote {target}")
