#!/usr/bin/python3
"""Asserts that runs of one scene on different numbers of MPI ranks agree: the particle
tables (particle_table_NNNNN.R.csv, full precision, written with Output/Write particle
table = true) of the final output (or of the output at --time) matched by particle id;
each field group (positions, stresses) equal to --rtol relative to the group's largest
magnitude over all its components (sum-order round-off only).
  compare_np.py REFERENCE_DIR OTHER_DIR [OTHER_DIR ...] [--rtol 1e-10] [--fields a,b] [--time T]
Optionally (--migrated, --repartitioned) the other runs' history.csv must show points
changing rank (n_sent > 0 and the points per rank changing) and repartitions.
--spread DIR: a run whose difference from the reference is the round-off the comparison may show: a
second run of the reference's own setting (GPU runs, whose sums have no fixed order, differ from run
to run), or the reference's scene in double where the reference runs in float; each field may then
differ by up to --spread-factor (default 10) times DIR's own difference from the reference, or
--rtol, whichever is larger."""
import argparse
import glob
import os
import re
import sys

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "..", "scripts"))
import mpm_results  # noqa: E402


def final_table(output_dir, time=None):
    """The particle table of the last output (or of the output at `time`), merged over
    ranks, sorted by id; also the number of ranks and the output's time."""
    files = glob.glob(os.path.join(output_dir, "particle_table_*.csv"))
    if not files:
        sys.exit(f"FAILED: no particle_table_*.csv in {output_dir} (Output/Write particle table = true?)")
    times = [t for t, _ in mpm_results.pvd_records(output_dir)]
    last = max(int(re.search(r"particle_table_(\d+)\.", f).group(1)) for f in files)
    if time is not None:
        last = int(np.argmin(np.abs(np.array(times) - time)))
    pieces = sorted(glob.glob(os.path.join(output_dir, f"particle_table_{last:05d}.*.csv")))
    names = open(pieces[0]).readline().strip().split(",")
    rows = [np.loadtxt(p, delimiter=",", skiprows=1, ndmin=2) for p in pieces]
    data = np.concatenate([r for r in rows if r.size])
    data = data[np.argsort(data[:, 0], kind="stable")]
    return {n: data[:, k] for k, n in enumerate(names)}, len(pieces), times[last]


parser = argparse.ArgumentParser(description=__doc__)
parser.add_argument("reference")
parser.add_argument("others", nargs="+")
parser.add_argument("--rtol", type=float, default=1e-10)
parser.add_argument("--fields", default="position,stress")
parser.add_argument("--migrated", action="store_true")
parser.add_argument("--repartitioned", action="store_true")
parser.add_argument("--time", type=float, default=None)
parser.add_argument("--spread")
parser.add_argument("--spread-factor", type=float, default=10)
args = parser.parse_args()


def difference(ref, cur, prefix):
    group = [n for n in ref if n.startswith(prefix)]
    scale = max(np.max(np.abs(ref[n])) for n in group)
    return max(np.max(np.abs(cur[n] - ref[n])) for n in group) / max(scale, 1e-300)


failed = False
ref, _, _ = final_table(args.reference, args.time)
prefixes = args.fields.split(",")
tolerance = {prefix: args.rtol for prefix in prefixes}
if args.spread:
    again, _, _ = final_table(args.spread, args.time)
    for prefix in prefixes:
        spread = difference(ref, again, prefix)
        tolerance[prefix] = max(args.rtol, args.spread_factor * spread)
        print(f"{args.spread}: {prefix} differs from {args.reference} by {spread:.3e} (round-off); "
              f"tolerance {tolerance[prefix]:.1e}")
for other in args.others:
    cur, n_ranks, time = final_table(other, args.time)
    if not np.array_equal(ref["id"], cur["id"]):
        print(f"FAILED: {other}: particle ids differ from {args.reference} ({len(cur['id'])} vs {len(ref['id'])})")
        failed = True
        continue
    report = []
    for prefix in prefixes:
        diff = difference(ref, cur, prefix)
        report.append(f"{prefix} {diff:.3e}")
        if not diff <= tolerance[prefix]:
            print(f"FAILED: {other}: {prefix} differs by {diff:.3e} relative (tolerance {tolerance[prefix]:.1e})")
            failed = True
    print(f"{other}: {len(cur['id'])} points on {n_ranks} rank(s) at t = {time:.6g} s; largest difference "
          f"relative to the field's magnitude: {', '.join(report)}")
    h = mpm_results.history(other)
    if args.migrated:
        sent, lo, hi = h["n_sent"][-1], h["min_points_per_rank"], h["max_points_per_rank"]
        changed = len(set(lo)) > 1 or len(set(hi)) > 1
        conserved = np.all(h["n_points"] == h["n_points"][0])
        print(f"  {int(sent)} points migrated; points per rank from [{int(lo[0])}, {int(hi[0])}] to "
              f"[{int(lo[-1])}, {int(hi[-1])}]; total {int(h['n_points'][-1])} (constant: {conserved})")
        if not (sent > 0 and changed and conserved):
            print("FAILED: no migration seen, or the total number of points changed")
            failed = True
    if args.repartitioned:
        print(f"  {int(h['n_repartitions'][-1])} repartitions, {int(h['n_resorts'][-1])} re-sorts")
        if not h["n_repartitions"][-1] >= 1:
            print("FAILED: the grid was never repartitioned")
            failed = True
sys.exit(1 if failed else 0)
