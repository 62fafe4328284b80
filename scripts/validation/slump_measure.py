#!/usr/bin/python3
"""Measure a slope failure (V5 slump) between two outputs of a dealii-mpm run (x horizontal,
vertical = the last coordinate; 2D or 3D).

Usage: slump_measure.py OUTPUT_DIR --start T0 [--time T] [--threshold D] [checks] [--json FILE]

Points are matched by id between the output at time T0 (the plasticity start: the geostatic,
elastic state) and the output at time T (default: the last). A point whose displacement since T0
exceeds --threshold has failed. Reported, all from the configuration at T0 unless said otherwise:
  displaced      number and fraction of the points that failed, and the volume they fill (m^3,
                 and m^2 per metre of width: divided by the extent in y in 3D);
  crest drop     the crest height at T0 minus the highest point at T within half a column of the
                 crest's x;
  crown          the smallest x of a failed point within one --bin of the top surface of its column:
                 where the scarp cuts the top; and the crest (largest x of the flat top, points within
                 --bin of the highest surface) for comparison; in 3D also per slab of width --bin
                 along y: its smallest, largest and standard deviation (a straight or curved crown);
  depth          per column of width --bin, the surface (highest point) minus the lowest failed point:
                 the depth of the failure surface; its largest value and where;
  run-out        the front of the slope material (points starting above --base-top) at T, minus its
                 toe at T0 (largest x at T0);
  back           the largest displacement of the points starting at x < --back: the ground behind the
                 slide, which must stay at rest for a slump.
Checks (exit status 1 if one fails): --fraction LO,HI  --crown LO,HI  --depth LO,HI  --back-max D
  --run-out LO,HI  --crest-drop LO,HI.
"""
import argparse
import json
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))  # scripts/: mpm_results
import mpm_results  # noqa: E402


def output_index(output_dir, time):
    """Index of the output nearest to `time` (None: the last)."""
    records = mpm_results.pvd_records(output_dir)
    if time is None:
        return len(records) - 1
    return int(np.argmin([abs(t - time) for t, _ in records]))


def by_id(data):
    order = np.argsort(data["id"])
    return {k: (v[order] if isinstance(v, np.ndarray) and len(v) == len(order) else v) for k, v in data.items()}


def measure(start, end, threshold, bin_width, base_top, back):
    start, end = by_id(start), by_id(end)
    common, i0, i1 = np.intersect1d(start["id"], end["id"], return_indices=True)
    x0, x1 = start["position"][i0], end["position"][i1]
    vol0 = start["volume"][i0]
    dim = x0.shape[1]
    if dim == 3 and not np.any(start["position"][:, 2]) and not np.any(end["position"][:, 2]):
        dim, x0, x1 = 2, x0[:, :2], x1[:, :2]  # 2D output, written with z = 0
    disp = np.linalg.norm(x1 - x0, axis=1)
    failed = disp > threshold
    z0 = x0[:, dim - 1]
    width = float(x0[:, 1].max() - x0[:, 1].min() + 2 * start["domain_half_length"][i0][:, 1].max()) if dim == 3 \
        else 1.0

    col = np.floor(x0[:, 0] / bin_width).astype(int)
    surface = {c: z0[col == c].max() for c in np.unique(col)}
    surf = np.array([surface[c] for c in col])
    top = z0.max()
    r = {
        "time_start": float(start["time"]), "time": float(end["time"]), "threshold": threshold,
        "n_points": int(len(common)), "n_lost": int(len(start["id"]) - len(common)),
        "n_displaced": int(failed.sum()), "fraction_displaced": float(failed.mean()),
        "volume_displaced": float(vol0[failed].sum()), "width": width,
        "area_displaced_per_width": float(vol0[failed].sum() / width),
        "max_displacement": float(disp.max()),
        "crest_x": float(x0[z0 > top - bin_width, 0].max()),
    }
    # Crest drop: the surface above the crest at T (highest point within half a column of the
    # crest's x, in the deformed configuration) against the crest height at T0.
    crest = r["crest_x"]
    above = np.abs(x1[:, 0] - crest) <= 0.5 * bin_width
    r["crest_height"] = float(top)
    r["crest_drop"] = float(top - x1[above, dim - 1].max()) if above.any() else float(top)
    near_top = failed & (z0 > surf - bin_width)
    r["crown_x"] = float(x0[near_top, 0].min()) if near_top.any() else float("nan")
    if dim == 3 and near_top.any():  # the crown along the width: straight or curved
        slab = np.floor((x0[:, 1] - x0[:, 1].min()) / bin_width + 1e-9).astype(int)
        crowns = [x0[near_top & (slab == k), 0].min() for k in np.unique(slab) if (near_top & (slab == k)).any()]
        r["crown_x_across_width"] = {"n_slabs": len(crowns), "min": float(np.min(crowns)),
                                     "max": float(np.max(crowns)), "std": float(np.std(crowns))}
    depth, where = 0.0, float("nan")
    for c in np.unique(col[failed]):
        d = surface[c] - z0[failed & (col == c)].min()
        if d > depth:
            depth, where = float(d), float((c + 0.5) * bin_width)
    r["max_failure_depth"], r["max_failure_depth_x"] = depth, where
    slope = z0 > base_top
    if slope.any():
        r["toe_start"] = float(x0[slope, 0].max())
        r["front"] = float(x1[slope, 0].max())
        r["run_out"] = r["front"] - r["toe_start"]
    behind = x0[:, 0] < back
    r["back_max_displacement"] = float(disp[behind].max()) if behind.any() else float("nan")
    r["_x0"], r["_disp"], r["_failed"] = x0, disp, failed
    return r


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("output_dir")
    parser.add_argument("--start", type=float, required=True, help="time of the reference state (s)")
    parser.add_argument("--time", type=float, help="time measured (s); default: the last output")
    parser.add_argument("--threshold", type=float, default=0.5, help="displacement of a failed point (m)")
    parser.add_argument("--bin", type=float, default=0.8, help="column width (m), e.g. the cell size")
    parser.add_argument("--base-top", type=float, default=1.92, help="top of the base layer (m)")
    parser.add_argument("--back", type=float, default=5.0, help="x below which the ground must stay (m)")
    parser.add_argument("--json")
    parser.add_argument("--fraction", type=mpm_results.bounds)
    parser.add_argument("--crown", type=mpm_results.bounds)
    parser.add_argument("--depth", type=mpm_results.bounds)
    parser.add_argument("--back-max", type=float)
    parser.add_argument("--run-out", type=mpm_results.bounds)
    parser.add_argument("--crest-drop", type=mpm_results.bounds)
    args = parser.parse_args()

    start = mpm_results.particles_at(args.output_dir, output_index(args.output_dir, args.start))
    end = mpm_results.particles_at(args.output_dir, output_index(args.output_dir, args.time))
    r = measure(start, end, args.threshold, args.bin, args.base_top, args.back)
    print(f"slump of {args.output_dir}: t = {r['time_start']:.3g} -> {r['time']:.3g} s, {r['n_points']} points "
          f"({r['n_lost']} lost)")
    print(f"  displaced > {r['threshold']:g} m: {r['n_displaced']} points ({100 * r['fraction_displaced']:.1f}%), "
          f"{r['volume_displaced']:.1f} m^3 = {r['area_displaced_per_width']:.1f} m^2 per metre of width; "
          f"largest displacement {r['max_displacement']:.2f} m")
    bin_width = args.bin
    print(f"  crown at x = {r['crown_x']:.2f} m (crest at {r['crest_x']:.2f} m); failure surface down to "
          f"{r['max_failure_depth']:.2f} m below the surface (at x = {r['max_failure_depth_x']:.1f} m)")
    print(f"  crest (x = {r['crest_x']:.2f} m, height {r['crest_height']:.2f} m) dropped by {r['crest_drop']:.2f} m")
    if "crown_x_across_width" in r:
        c = r["crown_x_across_width"]
        print(f"  crown across the width ({c['n_slabs']} slabs of {bin_width:g} m): x from {c['min']:.2f} to "
              f"{c['max']:.2f} m, standard deviation {c['std']:.2f} m")
    if "run_out" in r:
        print(f"  slope material: toe {r['toe_start']:.2f} m -> front {r['front']:.2f} m, run-out "
              f"{r['run_out']:.2f} m")
    print(f"  ground behind x = {args.back:g} m: largest displacement {r['back_max_displacement']:.3f} m")
    if args.json:
        with open(args.json, "w") as f:
            json.dump({k: v for k, v in r.items() if not k.startswith("_")}, f, indent=1)

    failed = mpm_results.check_limits((("fraction displaced", r["fraction_displaced"], args.fraction),
                                       ("crown x", r["crown_x"], args.crown),
                                       ("failure depth", r["max_failure_depth"], args.depth),
                                       ("run-out", r.get("run_out", float("nan")), args.run_out),
                                       ("crest drop", r["crest_drop"], args.crest_drop),
                                       ("back displacement", r["back_max_displacement"],
                                        None if args.back_max is None else (0.0, args.back_max))))
    sys.exit(1 if failed else 0)


if __name__ == "__main__":
    main()
