#!/usr/bin/python3
"""Measure the deposit of a 2D collapse / run-out (vertical = y, wall at x = --wall).

Usage: deposit.py OUTPUT_DIR [--png deposit.png] [--json deposit.json] [checks]

Reads the last particle output of a dealii-mpm run (scripts/mpm_results.py) and reports
  free surface   top of the material per column of width --bin: max(y + l_y) over the points
                 whose centre lies in the column (l_y: GIMP half-length, so that the undisturbed
                 column shows its true height, not that of the top row of point centres);
  run-out / toe  distance from the wall of the far edge (x + l_x) of the last column, counted from
                 the wall without a gap, whose surface stands at least --min-thickness above the
                 base (default: one column width, i.e. two rows of points at 2 points per cell;
                 a single row of points sliding along the base, 1.25 mm thick at h = 2.5 mm, is
                 thinner than one aluminium bar of the experiment and is not counted). The end
                 of everything reached without an empty column (thin layer included) and the
                 farthest point are reported too;
  top-left       surface height in the column at the wall;
  slope          least-squares line through the column heights of the sloping part: columns whose
                 height lies between --fit-low and --fit-high times the top-left height (the flat,
                 undisturbed cap near the wall and the thin tail at the toe are left out); angle =
                 atan(-fitted gradient);
  failure        points whose displacement |x - x0| exceeds --failure-threshold have failed; in the
                 initial configuration, per row of points the smallest x0 of a failed point is the
                 failure surface; a line is fitted through it and reported by its x at the top and
                 at the base of the column and its angle to the horizontal;
and draws the deposit coloured by accumulated plastic strain and the initial configuration
coloured by displacement with the failure surface (PNG).

Checks (exit status 1 when one fails): --toe LO,HI  --top-left LO,HI  --slope LO,HI (degrees).
"""
import argparse
import json
import math
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import mpm_results  # noqa: E402


def columns(x, top, x0, width):
    """Column index per point, and the surface (max top) per column."""
    k = np.floor((x - x0) / width).astype(int)
    k_max = int(k.max())
    surface = np.full(k_max + 1, np.nan)
    for j in range(k_max + 1):
        sel = k == j
        if np.any(sel):
            surface[j] = top[sel].max()
    return k, surface


def measure(data, wall=0.0, base=0.0, width=0.0025, fit_low=0.1, fit_high=0.9, threshold=1e-3,
            min_thickness=None):
    if min_thickness is None:
        min_thickness = width
    alive = np.ones(len(data["position"]), dtype=bool)
    if "material_id" in data:
        alive = data["material_id"] >= 0
    pos = data["position"][alive]
    x, y = pos[:, 0] - wall, pos[:, 1] - base
    if "domain_half_length" not in data:
        print("deposit.py: no domain_half_length in the data (not among Output/Particle fields?): "
              "the surface is that of the point centres, without their domains", file=sys.stderr)
    lp = data.get("domain_half_length", np.zeros_like(data["position"]))[alive]
    top = y + lp[:, 1]
    right = x + lp[:, 0]

    k, surface = columns(x, top, 0.0, width)
    # The deposit: columns reached from the wall without an empty column.
    empty = np.flatnonzero(np.isnan(surface))
    last = (empty[0] - 1) if len(empty) else len(surface) - 1
    extent = float(right[k == last].max())
    detached = int(np.sum(k > last))
    thin = np.flatnonzero(surface[: last + 1] < min_thickness)
    last_thick = (thin[0] - 1) if len(thin) else last
    toe = float(right[k == last_thick].max())
    x_col = (np.arange(last + 1) + 0.5) * width
    h_col = surface[: last + 1]
    top_left = float(h_col[0])

    fit = (h_col > fit_low * top_left) & (h_col < fit_high * top_left)
    slope = {"angle_deg": float("nan"), "x_range": [float("nan")] * 2, "n_columns": int(fit.sum())}
    if fit.sum() >= 3:
        g, c = np.polyfit(x_col[fit], h_col[fit], 1)
        slope = {
            "angle_deg": math.degrees(math.atan(-g)),
            "gradient": float(g),
            "intercept": float(c),
            "x_range": [float(x_col[fit].min() - width / 2), float(x_col[fit].max() + width / 2)],
            "n_columns": int(fit.sum()),
            "rms_residual": float(np.sqrt(np.mean((np.polyval([g, c], x_col[fit]) - h_col[fit]) ** 2))),
        }

    result = {
        "time": float(data.get("time", float("nan"))),
        "n_points": int(alive.sum()),
        "toe": toe,
        "min_thickness": min_thickness,
        "extent_with_thin_layer": extent,
        "farthest_point": float(right.max()),
        "detached_points": detached,
        "top_left_height": top_left,
        "max_height": float(np.nanmax(h_col)),
        "slope": slope,
        "overall_angle_deg": math.degrees(math.atan(top_left / toe)),
        "surface": {"x": x_col.tolist(), "height": h_col.tolist()},
        "column_width": width,
    }

    if "initial_position" in data:
        p0 = data["initial_position"][alive]
        x0, y0 = p0[:, 0] - wall, p0[:, 1] - base
        disp = np.hypot(pos[:, 0] - data["initial_position"][alive][:, 0], pos[:, 1] - p0[:, 1])
        failed = disp > threshold
        rows = np.unique(np.round(y0, 9))
        line_y, line_x = [], []
        for r in rows:
            sel = np.isclose(y0, r) & failed
            if np.any(sel):
                line_y.append(r)
                line_x.append(x0[sel].min())
        failure = {"threshold": threshold, "n_failed": int(failed.sum()), "rows": len(line_y)}
        if len(line_y) >= 3:
            a, b = np.polyfit(line_y, line_x, 1)  # x = a y + b
            y_top = float(y0.max() + lp[:, 1].max())
            failure.update({
                "x_at_base": float(b),
                "x_at_top": float(a * y_top + b),
                "angle_deg": math.degrees(math.atan2(1.0, -a)) if a != 0 else 90.0,
                "line": {"y": [float(v) for v in line_y], "x": [float(v) for v in line_x]},
            })
        result["failure"] = failure
        result["_disp"] = disp
        result["_initial"] = np.stack([x0, y0], axis=1)
    result["_xy"] = np.stack([x, y], axis=1)
    result["_eps_p"] = data.get("plastic_strain", np.zeros(len(x)))[alive]
    return result


def draw(result, png, title, reference):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    has_initial = "_initial" in result
    fig, axes = plt.subplots(2 if has_initial else 1, 1, figsize=(10, 6.4 if has_initial else 3.4),
                             squeeze=False)
    ax = axes[0, 0]
    xy, eps = result["_xy"], result["_eps_p"]
    order = np.argsort(eps)
    sc = ax.scatter(xy[order, 0], xy[order, 1], c=eps[order], s=1.5, cmap="viridis", vmin=0,
                    vmax=max(float(np.percentile(eps, 99)), 1e-12), rasterized=True)
    fig.colorbar(sc, ax=ax, label="accumulated plastic strain", pad=0.01)
    s = result["surface"]
    ax.plot(s["x"], s["height"], "k-", lw=0.8, label="free surface")
    sl = result["slope"]
    if np.isfinite(sl["angle_deg"]):
        xs = np.array(sl["x_range"])
        ax.plot(xs, sl["gradient"] * xs + sl["intercept"], "r--", lw=1.2,
                label=f"fit {sl['angle_deg']:.1f} deg")
    ax.axvline(result["toe"], color="C1", lw=0.8, ls=":", label=f"toe {result['toe']:.3f} m")
    ax.axvline(result["extent_with_thin_layer"], color="C7", lw=0.8, ls=":",
               label=f"thin layer to {result['extent_with_thin_layer']:.3f} m")
    if reference:
        ax.axvspan(0.42, 0.45, color="C3", alpha=0.12, label="toe, Bui et al. 2008")
        xr = np.array([0.0, 0.45])
        ax.plot(xr, 0.099 - math.tan(math.radians(14)) * xr, color="C3", lw=0.8, ls="-.",
                label="14 deg from 0.099 m (experiment)")
    ax.set_xlim(-0.005, max(result["farthest_point"], result["toe"], 0.46 if reference else 0) + 0.01)
    ax.set_ylim(-0.005, max(result["max_height"], 0.01) * 1.15)
    ax.set_aspect("equal")
    ax.set_xlabel("distance from the wall x (m)")
    ax.set_ylabel("height (m)")
    ax.legend(loc="upper right", fontsize=7, ncol=2)
    ax.set_title(f"{title}: deposit at t = {result['time']:.3g} s, top-left {result['top_left_height']:.4f} m, "
                 f"toe {result['toe']:.3f} m, slope {sl['angle_deg']:.1f} deg", fontsize=9)

    if has_initial:
        ax = axes[1, 0]
        p0, disp = result["_initial"], result["_disp"]
        f = result["failure"]
        sc = ax.scatter(p0[:, 0], p0[:, 1], c=disp, s=3, cmap="magma_r", rasterized=True)
        fig.colorbar(sc, ax=ax, label="displacement (m)", pad=0.01)
        if "line" in f:
            ax.plot(f["line"]["x"], f["line"]["y"], "c.", ms=3, label="first failed point per row")
            yy = np.array([0.0, max(f["line"]["y"])])
            a = (f["x_at_top"] - f["x_at_base"]) / (yy[1] if yy[1] > 0 else 1)
            ax.plot(f["x_at_base"] + a * yy, yy, "c-", lw=1.2,
                    label=f"failure surface fit, {f['angle_deg']:.0f} deg")
        if reference:
            ax.plot([0.18, 0.02], [0.0, 0.1], color="C3", lw=1, ls="-.", label="experiment (0.02 top, 0.18 base)")
        ax.set_aspect("equal")
        ax.set_xlabel("initial x (m)")
        ax.set_ylabel("initial height (m)")
        ax.legend(loc="upper right", fontsize=7)
        ax.set_title(f"initial configuration coloured by displacement; failed: |u| > {f['threshold']:g} m",
                     fontsize=9)
    fig.tight_layout()
    fig.savefig(png, dpi=160)
    plt.close(fig)


def add_arguments(parser, bin_help, png_help):
    """The options of this script and of deposit_3d.py (the same reading, on slabs in 3D)."""
    parser.add_argument("output_dir")
    parser.add_argument("--index", type=int, default=-1, help="output number (default: the last)")
    parser.add_argument("--wall", type=float, default=0.0, help="x of the wall (m)")
    parser.add_argument("--base", type=float, default=0.0, help="height of the base (m)")
    parser.add_argument("--bin", type=float, default=0.0025, help=bin_help)
    parser.add_argument("--fit-low", type=float, default=0.1)
    parser.add_argument("--fit-high", type=float, default=0.9)
    parser.add_argument("--failure-threshold", type=float, default=1e-3, help="displacement (m)")
    parser.add_argument("--min-thickness", type=float, help="toe: least deposit height (m); default --bin")
    parser.add_argument("--png", help=png_help)
    parser.add_argument("--reference", action="store_true", help="draw the V3 experiment (Bui et al. 2008)")
    parser.add_argument("--json", help="write the numbers here")
    parser.add_argument("--toe", type=mpm_results.bounds)
    parser.add_argument("--top-left", type=mpm_results.bounds)
    parser.add_argument("--slope", type=mpm_results.bounds)


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    add_arguments(parser, "column width (m), e.g. the cell size", "picture of the deposit")
    parser.add_argument("--title", default="")
    args = parser.parse_args()

    data = mpm_results.particles_at(args.output_dir, args.index)
    r = measure(data, args.wall, args.base, args.bin, args.fit_low, args.fit_high, args.failure_threshold,
                args.min_thickness)
    sl = r["slope"]
    print(f"deposit of {args.output_dir} at t = {r['time']:.4g} s ({r['n_points']} points)")
    print(f"  toe (run-out from the wall, deposit >= {r['min_thickness']:g} m thick) {r['toe']:.4f} m; "
          f"with the thin layer {r['extent_with_thin_layer']:.4f} m; farthest point {r['farthest_point']:.4f} m "
          f"({r['detached_points']} points beyond the first empty column)")
    print(f"  top-left height {r['top_left_height']:.4f} m; highest column {r['max_height']:.4f} m")
    print(f"  surface slope {sl['angle_deg']:.2f} deg (fit over {sl['n_columns']} columns, x in "
          f"[{sl['x_range'][0]:.4f}, {sl['x_range'][1]:.4f}] m, heights {args.fit_low:g}-{args.fit_high:g} of "
          f"the top-left); overall atan(top-left / toe) {r['overall_angle_deg']:.2f} deg")
    if "failure" in r and "x_at_top" in r["failure"]:
        f = r["failure"]
        print(f"  failure surface (|u| > {f['threshold']:g} m, {f['n_failed']} points): x = {f['x_at_top']:.4f} m "
              f"at the top, {f['x_at_base']:.4f} m at the base, {f['angle_deg']:.1f} deg to the horizontal")
    if args.png:
        draw(r, args.png, args.title or os.path.basename(os.path.normpath(args.output_dir)), args.reference)
        print(f"  picture: {args.png}")
    if args.json:
        with open(args.json, "w") as f:
            json.dump({k: v for k, v in r.items() if not k.startswith("_")}, f, indent=1)

    failed = mpm_results.check_limits((("toe", r["toe"], args.toe), ("top-left height", r["top_left_height"], args.top_left),
                                       ("slope", sl["angle_deg"], args.slope)))
    sys.exit(1 if failed else 0)


if __name__ == "__main__":
    main()
