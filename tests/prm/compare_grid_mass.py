#!/usr/bin/python3
"""Grid/Nodes = near material writes only the cells with mass at a vertex: asserts that the last
grid output of a near-material run (NEAR_DIR) holds fewer vertices than that of Nodes = all
(ALL_DIR) and the same nodal masses and velocities at every vertex that has mass in either: equal
(CPU: bit for bit), or within --rtol of each field's largest magnitude (GPU: atomics sum in no
fixed order). --spread DIR: a second run with Nodes = all; the values may then differ by up to
--spread-factor (default 10) times its own difference from ALL_DIR, or --rtol, whichever is larger.
--same-cells: the second output must hold as many vertex entries as the first (Grid/Cells per
deal.II cell, where every cell is written by either run) instead of fewer.
  compare_grid_mass.py ALL_DIR NEAR_DIR [--rtol R] [--time T] [--spread DIR [--spread-factor F]] [--same-cells]"""
import argparse
import os
import sys

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "..", "scripts"))
import mpm_results  # noqa: E402


def vertices_with_mass(output_dir, time=None):
    """{vertex position (rounded): (mass, velocity...)} of the last grid output (or the one nearest
    `time`), and its number of vertex entries (each cell lists its own)."""
    records = mpm_results.pvd_records(output_dir, "grid")
    index = -1 if time is None else int(np.argmin([abs(t - time) for t, _ in records]))
    _, pvtu = records[index]
    data = mpm_results.read_pvtu(output_dir, pvtu)
    names = ["nodal_mass"] + sorted(k for k in data if k.startswith("nodal_velocity"))
    values = np.column_stack([data[k] for k in names])
    keys = [tuple(np.round(p, 9)) for p in data["position"]]
    return {k: tuple(v) for k, v in zip(keys, values) if v[0] != 0}, len(keys)


parser = argparse.ArgumentParser(description=__doc__)
parser.add_argument("all_dir")
parser.add_argument("near_dir")
parser.add_argument("--rtol", type=float, default=0.0)
parser.add_argument("--time", type=float, default=None)
parser.add_argument("--spread")
parser.add_argument("--spread-factor", type=float, default=10)
parser.add_argument("--same-cells", action="store_true")
args = parser.parse_args()
everywhere, n_all = vertices_with_mass(args.all_dir, args.time)
near, n_near = vertices_with_mass(args.near_dir, args.time)
if args.same_cells and n_near != n_all:
    sys.exit(f"FAILED: the second grid output has {n_near} vertex entries, the first {n_all}")
if not args.same_cells and not n_near < n_all:
    sys.exit(f"FAILED: the near-material grid output has {n_near} vertex entries, Nodes = all {n_all}")
if everywhere.keys() != near.keys():
    sys.exit(f"FAILED: {len(everywhere.keys() ^ near.keys())} vertices have mass in one grid output only")
a = np.array([everywhere[k] for k in sorted(everywhere)])
scale = np.maximum(np.abs(a).max(axis=0), 1e-300)


def worst_difference(other):
    b = np.array([other.get(k, (0.0,) * a.shape[1]) for k in sorted(everywhere)])
    return (np.abs(a - b) / scale).max()


allowed = args.rtol
if args.spread:
    again, _ = vertices_with_mass(args.spread, args.time)
    spread = worst_difference(again)
    allowed = max(args.rtol, args.spread_factor * spread)
    print(f"grid output: two runs with every node differ by {spread:.3e} of the largest magnitude; allowed {allowed:.1e}")
worst = worst_difference(near)
if not worst <= allowed:
    sys.exit(f"FAILED: the nodal values differ by {worst:.3e} of their largest magnitude (allowed {allowed:.1e})")
print(f"grid output: {n_near} vertex entries against {n_all}; the {len(near)} vertices with mass agree "
      f"(largest difference {worst:.3e} of the largest magnitude)")
