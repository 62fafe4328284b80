#!/usr/bin/python3
"""Measure the deposit of a 3D collapse / run-out (vertical = z, wall at x = --wall, width along y)
with the 2D reading of scripts/deposit.py, on slabs of the width.

Usage: deposit_3d.py OUTPUT_DIR [--bin W] [--png deposit.png] [--json deposit.json] [checks]

The points are cut into slabs along y of width --bin by their initial y (points hardly move across
a plane-strain slab; the initial y keeps every point in one slab). Each slab is measured as a 2D
deposit in the (x, z) plane by deposit.measure (toe, top-left height, free-surface slope, failure
surface: see deposit.py). Reported:
  mid-plane      the slab that holds the middle of the width (the points within --bin / 2 of it);
  across width   the mean of the slabs' numbers, with their smallest and largest value.
Checks (exit status 1 when one fails): --toe LO,HI  --top-left LO,HI  --slope LO,HI (degrees); each
applies to the mid-plane value and to the mean across the width.
"""
import argparse
import json
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import deposit  # noqa: E402
import mpm_results  # noqa: E402

XZ = [0, 2]  # the vertical plane of the 2D reading


def slab(data, selected):
    """The points `selected` as 2D data in the (x, z) plane, in the form deposit.measure reads."""
    out = {"time": data.get("time", float("nan"))}
    for key in ("position", "initial_position", "domain_half_length"):
        if key in data:
            out[key] = data[key][selected][:, XZ]
    for key in ("material_id", "plastic_strain"):
        if key in data:
            out[key] = data[key][selected]
    return out


def slab_numbers(result):
    f = result.get("failure", {})
    return {"toe": result["toe"], "top_left_height": result["top_left_height"],
            "slope_deg": result["slope"]["angle_deg"], "extent_with_thin_layer": result["extent_with_thin_layer"],
            "failure_x_at_top": f.get("x_at_top", float("nan")), "failure_x_at_base": f.get("x_at_base", float("nan"))}


def measure_3d(data, wall, base, width, fit_low, fit_high, threshold, min_thickness):
    y = (data["initial_position"] if "initial_position" in data else data["position"])[:, 1]
    y_lo, y_hi = y.min(), y.max()
    mid = 0.5 * (y_lo + y_hi)
    args = (wall, base, width, fit_low, fit_high, threshold, min_thickness)
    distance = np.abs(y - mid)
    near_mid = distance <= 0.5 * width + 1e-12
    if not near_mid.any():  # the points' spacing is wider than the slab: take the layer nearest the middle
        near_mid = distance <= distance.min() + 1e-12
    mid_result = deposit.measure(slab(data, near_mid), *args)
    k = np.floor((y - y_lo) / width + 1e-9).astype(int)
    slabs = [slab_numbers(deposit.measure(slab(data, k == j), *args)) for j in np.unique(k)]
    across = {}
    for name in slabs[0]:
        v = np.array([s[name] for s in slabs], dtype=float)
        across[name] = {"mean": float(np.nanmean(v)), "min": float(np.nanmin(v)), "max": float(np.nanmax(v))}
    return {"time": float(data.get("time", float("nan"))), "n_points": int(len(y)), "n_slabs": len(slabs),
            "y_range": [float(y_lo), float(y_hi)], "mid_plane": slab_numbers(mid_result),
            "across_width": across, "_mid_result": mid_result}


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    deposit.add_arguments(parser, "column and slab width (m), e.g. the cell size", "picture of the mid-plane deposit")
    args = parser.parse_args()

    data = mpm_results.particles_at(args.output_dir, args.index)
    r = measure_3d(data, args.wall, args.base, args.bin, args.fit_low, args.fit_high, args.failure_threshold,
                   args.min_thickness)
    m, a = r["mid_plane"], r["across_width"]
    print(f"3D deposit of {args.output_dir} at t = {r['time']:.4g} s ({r['n_points']} points, {r['n_slabs']} slabs "
          f"of {args.bin:g} m across y in [{r['y_range'][0]:.4g}, {r['y_range'][1]:.4g}] m)")
    for name, unit in (("toe", "m"), ("top_left_height", "m"), ("slope_deg", "deg"), ("extent_with_thin_layer", "m"),
                       ("failure_x_at_top", "m"), ("failure_x_at_base", "m")):
        print(f"  {name:24s} mid-plane {m[name]:.4f} {unit}; across the width mean {a[name]['mean']:.4f} "
              f"(min {a[name]['min']:.4f}, max {a[name]['max']:.4f})")
    if args.png:
        deposit.draw(r["_mid_result"], args.png, os.path.basename(os.path.normpath(args.output_dir)) + ", mid-plane",
                     args.reference)
        print(f"  picture: {args.png}")
    if args.json:
        with open(args.json, "w") as f:
            json.dump({k: v for k, v in r.items() if not k.startswith("_")}, f, indent=1)

    failed = mpm_results.check_limits(
        (f"{name} ({where})", value, lim)
        for name, key, lim in (("toe", "toe", args.toe), ("top-left height", "top_left_height", args.top_left),
                               ("slope", "slope_deg", args.slope))
        for where, value in (("mid-plane", m[key]), ("mean across the width", a[key]["mean"])))
    sys.exit(1 if failed else 0)


if __name__ == "__main__":
    main()
