#!/usr/bin/python3
"""Run-out of a collapsed quarter column (V6, prm/column_aspect_ratio_3d.prm), read at the dense
front as the experiment reads it (the mean of 6 radii).

Usage: column_runout.py OUTPUT_DIR --cell H [--points-per-cell N] [--r0 1] [--lambda L]
                        [--json FILE] [--check-fit TOLERANCE]

Reads the last particle table of a run (particle_table_NNNNN.R.csv, Output/Write particle table
= true; every rank's file of that output) and measures:
  thickness   in 6 sectors of 15 degrees about the column's axis (the z axis), radial bins of width
              H: the points' volume in a bin over the bin's area, the deposit's thickness there;
  front       per sector, walking out from r = r0 / 2, the inner edge of the first bin thinner than
              one point spacing (H / N): the dense front; a thin veil of scattered points beyond
              it does not count, as in the experiment;
  run-out     r_inf, the mean of the 6 fronts, and (r_inf - r0) / r0 with the fit 0.63 lambda^1.30
              of the experiments (Wyser 2022, ch. 7) when --lambda is given;
  height      h_inf, the deposit's height at the axis (the highest point within r0 / 10 of it,
              plus half a point spacing).
--check-fit T: exit status 1 unless |run-out - fit| <= T (absolute, in units of r0).
Needs only numpy (runs on the GPU hosts too).
"""
import argparse
import glob
import json
import math
import os
import sys

import numpy as np

SECTORS = 6


def last_table(output_dir):
    """Positions and volumes of every point of the last particle-table output (all ranks)."""
    files = sorted(glob.glob(os.path.join(output_dir, "particle_table_*.csv")))
    if not files:
        sys.exit(f"column_runout.py: no particle_table_*.csv in {output_dir} (Output/Write particle table = true)")
    last = os.path.basename(files[-1]).split(".")[0]
    parts = [f for f in files if os.path.basename(f).split(".")[0] == last]
    columns = None
    blocks = []
    for name in parts:
        with open(name) as f:
            header = f.readline().strip().split(",")
        if columns is None:
            columns = [header.index(c) for c in ("position_x", "position_y", "position_z", "volume")]
        blocks.append(np.loadtxt(name, delimiter=",", skiprows=1, usecols=columns, ndmin=2))
    data = np.concatenate(blocks)
    return data[:, :3], data[:, 3]


def measure(position, volume, cell, points_per_cell=2, r0=1.0):
    x, y, z = position.T
    r = np.hypot(x, y)
    theta = np.arctan2(y, x)
    spacing = cell / points_per_cell
    width = math.pi / 2 / SECTORS
    n_bins = int(math.ceil(r.max() / cell)) + 1
    edges = np.arange(n_bins + 1) * cell
    fronts, profiles = [], []
    for s in range(SECTORS):
        inside = (theta >= s * width) & (theta < (s + 1) * width if s < SECTORS - 1 else theta <= math.pi / 2 + 1e-12)
        sums, _ = np.histogram(r[inside], bins=edges, weights=volume[inside])
        area = 0.5 * width * (edges[1:] ** 2 - edges[:-1] ** 2)
        thickness = sums / area
        k = int(0.5 * r0 / cell)
        while k < n_bins and thickness[k] >= spacing:
            k += 1
        fronts.append(float(edges[k]))
        profiles.append(thickness.tolist())
    near_axis = r < 0.1 * r0
    height = float(z[near_axis].max() + 0.5 * spacing) if np.any(near_axis) else 0.0
    r_inf = float(np.mean(fronts))
    return {"fronts": fronts, "r_inf": r_inf, "runout": (r_inf - r0) / r0, "height": height,
            "spread": float(np.std(fronts)), "bin": cell, "thickness_profiles": profiles,
            "n_points": int(len(volume)), "volume": float(volume.sum())}


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("output_dir")
    parser.add_argument("--cell", type=float, required=True, help="grid cell size H (m)")
    parser.add_argument("--points-per-cell", type=int, default=2, help="points per cell direction N")
    parser.add_argument("--r0", type=float, default=1.0)
    parser.add_argument("--lambda", dest="aspect_ratio", type=float, default=None)
    parser.add_argument("--json", default=None)
    parser.add_argument("--check-fit", type=float, default=None)
    args = parser.parse_args()

    position, volume = last_table(args.output_dir)
    result = measure(position, volume, args.cell, args.points_per_cell, args.r0)
    line = (f"run-out: fronts {', '.join(f'{f:.3f}' for f in result['fronts'])} m; r_inf = {result['r_inf']:.4f} m "
            f"(spread {result['spread']:.3f}), (r_inf - r0)/r0 = {result['runout']:.4f}; h_inf = {result['height']:.4f} m")
    status = 0
    if args.aspect_ratio is not None:
        result["lambda"] = args.aspect_ratio
        result["fit"] = 0.63 * args.aspect_ratio ** 1.30
        result["error"] = result["runout"] / result["fit"] - 1
        line += f"; fit {result['fit']:.4f}, error {100 * result['error']:+.1f}%"
        if args.check_fit is not None:
            ok = abs(result["runout"] - result["fit"]) <= args.check_fit
            line += f" ({'within' if ok else 'NOT within'} {args.check_fit:.3f} of the fit)"
            status = 0 if ok else 1
    print(line)
    if args.json:
        with open(args.json, "w") as f:
            json.dump(result, f)
    return status


if __name__ == "__main__":
    sys.exit(main())
