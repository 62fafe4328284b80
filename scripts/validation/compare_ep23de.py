#!/usr/bin/python3
"""Point-by-point comparison of a dealii-mpm run of prm/slump_3d_ep23de.prm (homogeneous) with ep2-3De's
own run of the same scene (../shared/reference/ep23de-v5-homogeneous: points_tNNs.csv.gz).

Usage: compare_ep23de.py OUTPUT_DIR REFERENCE_DIR [--times 8,10,12,15] [--prefix points] [--start 8]

The two codes hold the same points: ep2-3De lists them as MATLAB's meshgrid(x, z, y)(:) leaves them (z
fastest, then x, then y); our points are put in that order by their initial positions. For each time:
the distance between the same point in the two runs (median, RMS, largest), and, from --start on, the
fraction of the points displaced by more than 1 m since --start in each run and in both.
"""
import argparse
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))  # scripts/: mpm_results
import mpm_results  # noqa: E402


def ours_at(output_dir, time):
    records = mpm_results.pvd_records(output_dir)
    index = int(np.argmin([abs(t - time) for t, _ in records]))
    data = mpm_results.particles_at(output_dir, index)
    x0 = np.round(data["initial_position"], 6)
    order = np.lexsort((x0[:, 2], x0[:, 0], x0[:, 1]))
    return data["position"][order]


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("output_dir")
    ap.add_argument("reference_dir")
    ap.add_argument("--times", default="8,10,12,15")
    ap.add_argument("--prefix", default="points", help="reference file prefix (points_component_damping: the "
                                                           "per-component run)")
    ap.add_argument("--start", type=float, default=8.0)
    args = ap.parse_args()
    times = [float(t) for t in args.times.split(",")]
    ref = {t: np.loadtxt(os.path.join(args.reference_dir, f"{args.prefix}_t{int(t):02d}s.csv.gz"), delimiter=",",
                         skiprows=1)[:, :3] for t in times}
    ours = {t: ours_at(args.output_dir, t) for t in times}
    if len(ours[times[0]]) != len(ref[times[0]]):
        sys.exit(f"different point sets: {len(ours[times[0]])} points here, {len(ref[times[0]])} in the reference")
    for t in times:
        d = np.linalg.norm(ours[t] - ref[t], axis=1)
        line = f"t = {t:g} s: same point apart by median {np.median(d):.3f} m, RMS {np.sqrt(np.mean(d**2)):.3f} m, " \
               f"largest {d.max():.3f} m"
        if t > args.start and args.start in ours:
            mine = np.linalg.norm(ours[t] - ours[args.start], axis=1) > 1
            theirs = np.linalg.norm(ref[t] - ref[args.start], axis=1) > 1
            line += f"; displaced > 1 m since {args.start:g} s: {100 * mine.mean():.1f}% here, " \
                    f"{100 * theirs.mean():.1f}% ep2-3De, {100 * (mine & theirs).mean():.1f}% both"
        print(line)


if __name__ == "__main__":
    main()
