#!/usr/bin/env python3
"""V2 cantilever (../shared/BENCHMARKS.md): the tip's vertical deflection over time from the
particle tables of a run (Output/Write particle table = true).

The tip is the last column of points of the beam at t = 0 (x within a sixth of a cell of the
largest x); its deflection is the mean vertical displacement of those points. Prints the
first deflection minimum (the first sample lower than both neighbours) and its time, and
optionally writes the history as CSV. Output times are k * interval (dealii-mpm's steps
land on them).

It also reports the smallest GIMP domain half-length over its initial value, over every point,
axis and output: where the F_ii domain update lets the domains vanish under the beam's
rotation, this goes to zero.

Usage: cantilever_tip.py OUTDIR --interval DT [--cell H] [--csv FILE]
       [--check-minimum LO,HI] [--check-time LO,HI] [--check-domain-scale LO,HI]
"""
import argparse
import csv
import glob
import os
import re
import sys


def read_table(path):
    """({id: (x, y)}, smallest domain half-length over its initial value)"""
    with open(path) as f:
        rows = list(csv.DictReader(f))
    scale = min(float(r[f"domain_half_length_{a}"]) / float(r[f"initial_domain_half_length_{a}"])
                for r in rows for a in "xy")
    return {int(r["id"]): (float(r["position_x"]), float(r["position_y"])) for r in rows}, scale


def tables(directory):
    """{output number: [files of that output, one per rank]}"""
    found = {}
    for path in glob.glob(os.path.join(directory, "particle_table_*.csv")):
        m = re.match(r"particle_table_(\d+)\.(\d+)\.csv$", os.path.basename(path))
        if m:
            found.setdefault(int(m.group(1)), []).append(path)
    return dict(sorted(found.items()))


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("directory")
    ap.add_argument("--interval", type=float, required=True, help="Output interval of the run (s)")
    ap.add_argument("--cell", type=float, default=0.25, help="cell size h (m)")
    ap.add_argument("--csv", help="write time, deflection to this file")
    ap.add_argument("--check-minimum", help="LO,HI: the first minimum's deflection must lie in [LO, HI] (m)")
    ap.add_argument("--check-time", help="LO,HI: the first minimum's time must lie in [LO, HI] (s)")
    ap.add_argument("--check-domain-scale", help="LO,HI: the smallest domain scale must lie in [LO, HI]")
    args = ap.parse_args()

    outputs = tables(args.directory)
    if 0 not in outputs:
        sys.exit(f"cantilever_tip.py: no particle_table_00000.*.csv in {args.directory}")
    start, smallest = {}, float("inf")
    for path in outputs[0]:
        start.update(read_table(path)[0])
    x_max = max(x for x, _ in start.values())
    tip = [i for i, (x, _) in start.items() if x > x_max - args.cell / 6]
    history = []
    for k, paths in outputs.items():
        now = {}
        for path in paths:
            points, scale = read_table(path)
            now.update(points)
            smallest = min(smallest, scale)
        missing = [i for i in tip if i not in now]
        if missing:  # the history ends where the beam has torn off the wall and left the grid
            print(f"{len(missing)} tip points gone at t = {k * args.interval:.3f} s (left the grid); "
                  "the history ends there")
            break
        dy = sum(now[i][1] - start[i][1] for i in tip) / len(tip)
        history.append((k * args.interval, dy))
    if args.csv:
        with open(args.csv, "w") as f:
            f.write("time,deflection\n")
            for t, d in history:
                f.write(f"{t:.6g},{d:.9g}\n")
    first = next((j for j in range(1, len(history) - 1)
                  if history[j][1] < history[j - 1][1] and history[j][1] <= history[j + 1][1]), None)
    if first is None:
        sys.exit("cantilever_tip.py: no deflection minimum in the run")
    t_min, d_min = history[first]
    print(f"V2 tip ({len(tip)} points): first deflection minimum {d_min:.4f} m at t = {t_min:.3f} s; "
          f"lowest {min(d for _, d in history):.4f} m; smallest domain scale {smallest:.3f}")
    ok = True
    for option, value, name in ((args.check_minimum, d_min, "deflection"), (args.check_time, t_min, "time"),
                                (args.check_domain_scale, smallest, "smallest domain scale")):
        if option:
            lo, hi = (float(v) for v in option.split(","))
            if not lo <= value <= hi:
                print(f"FAILED: {name} {value:.4f} outside [{lo}, {hi}]")
                ok = False
    sys.exit(0 if ok else 1)


if __name__ == "__main__":
    main()
