#!/usr/bin/python3
"""Side view (x-z) of 3D slump runs coloured by accumulated plastic strain, one panel per run:
the shear zones of homogeneous vs random cohesion (V5). Usage:
  slump_picture.py OUT.png LABEL1=OUTPUT_DIR1 [LABEL2=OUTPUT_DIR2 ...]"""
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

sys.path.insert(0, os.path.dirname(__file__))
import mpm_results  # noqa: E402

runs = [a.rsplit("=", 1) for a in sys.argv[2:]]
fig, axes = plt.subplots(len(runs), 1, figsize=(9, 2.6 * len(runs)), squeeze=False)
for ax, (label, out) in zip(axes[:, 0], runs):
    p = mpm_results.particles_at(out)
    x, z = p["position"][:, 0], p["position"][:, 2]
    order = np.argsort(p["plastic_strain"])  # strongest shear drawn on top
    sc = ax.scatter(x[order], z[order], c=np.clip(p["plastic_strain"][order], 0, 1), s=1.5, cmap="inferno_r",
                    vmin=0, vmax=1)
    ax.set_aspect("equal")
    ax.set_title(f"{label}, t = {p['time']:.3g} s")
    ax.set_ylabel("z (m)")
    fig.colorbar(sc, ax=ax, label="plastic strain (clipped at 1)", shrink=0.8)
axes[-1, 0].set_xlabel("x (m)")
fig.tight_layout()
fig.savefig(sys.argv[1], dpi=110)
print("wrote", sys.argv[1])
