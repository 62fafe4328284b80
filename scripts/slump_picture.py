#!/usr/bin/python3
"""Pictures of slump runs (V5 in 3D, V4 in 2D), one panel per run:
  side view (default): x-z (x-y in 2D), coloured by accumulated plastic strain: the shear zones;
  plan view (--plan START): the top surface seen from above at time START (the plasticity start),
    coloured by the displacement since then: where the scarp (crown) cuts the top, straight or curved.
Usage:
  slump_picture.py [--plan START] OUT.png LABEL1=OUTPUT_DIR1[@TIME] [LABEL2=OUTPUT_DIR2[@TIME] ...]
TIME (s) picks the output nearest to it (default: the last)."""
import argparse
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "validation"))  # slump_measure
import mpm_results  # noqa: E402
from slump_measure import by_id, output_index  # noqa: E402

parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
parser.add_argument("--plan", type=float, help="plan view of the displacement since this time (s)")
parser.add_argument("--vmax", type=float, default=2.0, help="colour scale top: displacement (m) in plan view")
parser.add_argument("png")
parser.add_argument("runs", nargs="+")
args = parser.parse_args()

runs = []
for a in args.runs:
    label, out = a.rsplit("=", 1)
    time = None
    if "@" in out:
        out, t = out.rsplit("@", 1)
        time = float(t)
    runs.append((label, out, time))

height = 3.2 if args.plan is not None else 2.6
fig, axes = plt.subplots(len(runs), 1, figsize=(9, height * len(runs)), squeeze=False)
for ax, (label, out, time) in zip(axes[:, 0], runs):
    p = mpm_results.particles_at(out, output_index(out, time))
    if args.plan is None:
        vertical = 2 if np.any(p["position"][:, 2]) else 1  # 2D output has z = 0
        x, z = p["position"][:, 0], p["position"][:, vertical]
        order = np.argsort(p["plastic_strain"])  # strongest shear drawn on top
        sc = ax.scatter(x[order], z[order], c=np.clip(p["plastic_strain"][order], 0, 1), s=1.5, cmap="inferno_r",
                        vmin=0, vmax=1)
        ax.set_ylabel("z (m)" if vertical == 2 else "y (m)")
        fig.colorbar(sc, ax=ax, label="plastic strain (clipped at 1)", shrink=0.8)
    else:
        s = by_id(mpm_results.particles_at(out, output_index(out, args.plan)))
        p = by_id(p)
        _, i0, i1 = np.intersect1d(s["id"], p["id"], return_indices=True)
        x0 = s["position"][i0]
        disp = np.linalg.norm(p["position"][i1] - x0, axis=1)
        # The top layer of points: within one point spacing of the highest point of its column.
        h = 2 * s["domain_half_length"][i0][:, 0].max()
        col = np.floor(x0[:, 0] / h).astype(int) * 100000 + np.floor(x0[:, 1] / h).astype(int)
        top = np.zeros(len(col), dtype=bool)
        for c in np.unique(col):
            sel = np.flatnonzero(col == c)
            top[sel[x0[sel, 2] > x0[sel, 2].max() - 0.5 * h]] = True
        sc = ax.scatter(x0[top, 0], x0[top, 1], c=np.clip(disp[top], 0, args.vmax), s=4, marker="s",
                        cmap="viridis", vmin=0, vmax=args.vmax)
        ax.set_ylabel("y (m)")
        fig.colorbar(sc, ax=ax, label=f"displacement since {args.plan:g} s (m)", shrink=0.8)
    ax.set_aspect("equal")
    ax.set_title(f"{label}, t = {p['time']:.3g} s" + (" (top surface at the plasticity start)" if args.plan else ""))
axes[-1, 0].set_xlabel("x (m)")
fig.tight_layout()
fig.savefig(args.png, dpi=110)
print("wrote", args.png)
