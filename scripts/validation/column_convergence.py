#!/usr/bin/python3
"""V1 elastic column convergence: runs dealii-mpm on prm/elastic_column_2d.prm at several
resolutions, for cpGIMP (F_ii domains), standard MPM and the cubic B-spline GIMP (F_ii domains, local
damping 0.5 and FLIP 0.99: at rest by the end, doc/methods.md), and writes
doc/column_convergence.csv and doc/figures/column_convergence.png (error vs cell size).
Usage: column_convergence.py [--exe build/dealii-mpm] [--levels 2,4,...] [--work /tmp/v1]"""
import argparse
import os
import subprocess
import sys

import numpy as np

here = os.path.dirname(os.path.abspath(__file__))
root = os.path.dirname(os.path.dirname(here))
sys.path.insert(0, os.path.dirname(here))  # scripts/: mpm_results
sys.path.insert(0, here)
from column_error import column_error  # noqa: E402

parser = argparse.ArgumentParser()
parser.add_argument("--exe", default=os.path.join(root, "build", "dealii-mpm"))
parser.add_argument("--levels", default="1,2,4,8,16,32,64,128,256")
parser.add_argument("--work", default="/tmp/v1-convergence")
args = parser.parse_args()

template = open(os.path.join(root, "prm", "elastic_column_2d.prm")).read()
# label: shape function, domain update, local damping, FLIP fraction
variants = {
    "cpGIMP (F_ii)": ("GIMP", "F_ii", 0.05, 1),
    "sMPM": ("linear", "none", 0.05, 1),
    "cubic B-spline GIMP (F_ii), D 0.5, FLIP 0.99": ("cubic B-spline GIMP", "F_ii", 0.5, 0.99),
}
rows = []
for label, (shape, update, damping, flip) in variants.items():
    for n in [int(v) for v in args.levels.split(",")]:
        h = 10.0 / n
        out = os.path.join(args.work, f"{shape.replace(' ', '_')}-{n}")
        os.makedirs(out, exist_ok=True)
        prm = template.replace("0.15625", repr(h))
        prm += f"""
subsection Solver
  set Shape function = {shape}
  set GIMP domain update = {update}
  set Local damping = {damping}
  set FLIP fraction = {flip}
end
subsection Output
  set Directory = {out}
  set Output interval = 0
  set Write grid fields = false
  set Progress interval = 0
end
"""
        path = os.path.join(out, "scene.prm")
        open(path, "w").write(prm)
        subprocess.run([args.exe, path], check=True, stdout=subprocess.DEVNULL)
        error, p = column_error(out)
        print(f"{label:15s} cells {n:4d} h {h:9.5f} points {len(p['mass']):5d} error {error:.4e}", flush=True)
        rows.append((label, n, h, error))

with open(os.path.join(root, "doc", "column_convergence.csv"), "w") as f:
    f.write("variant,cells,h,error\n")
    for r in rows:
        f.write(f"{r[0]},{r[1]},{r[2]:.6g},{r[3]:.6e}\n")

import matplotlib  # noqa: E402

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

fig, ax = plt.subplots(figsize=(5.5, 4.2))
for label, marker in zip(variants, "os^"):
    hs = np.array([r[2] for r in rows if r[0] == label])
    es = np.array([r[3] for r in rows if r[0] == label])
    ax.loglog(hs, es, marker + "-", label=label)
hs = np.array([r[2] for r in rows if r[0] == "cpGIMP (F_ii)"])
ref = 1e-3 * (hs / hs[len(hs) // 2]) ** 2
ax.loglog(hs, ref, "k--", lw=0.8, label="slope 2")
ax.set_xlabel("cell size h (m)")
ax.set_ylabel("stress error norm e")
ax.set_title("V1 elastic column, MUSL")
ax.grid(True, which="both", lw=0.3)
ax.legend(loc="lower right", fontsize=8)
fig.tight_layout()
fig.savefig(os.path.join(root, "doc", "figures", "column_convergence.png"), dpi=120)
print("wrote doc/column_convergence.csv and doc/figures/column_convergence.png")
