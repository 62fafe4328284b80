#!/usr/bin/env python3
"""Where a run of benchmarks/gpu-lab/gpu_float_runaway.sh ran away: from its particle tables
(Output/Write particle table), per output the fastest point (id, position, speed, the rank
holding it) and each rank's x-range of points, from the output before the kinetic energy
first grew tenfold over its smallest value after the heap came to rest (t >= 0.5 s).

  python3 float_runaway_where.py RUN_DIR OUTPUT_INTERVAL [FROM_TIME [EVERY]]

2D runs (velocity_x, velocity_y).

FROM_TIME (and every EVERY-th output from it) prints those outputs instead, whether the run ran away or not.
"""
import glob
import os
import re
import sys

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "scripts"))
import mpm_results  # noqa: E402


def tables(run):
    by_counter = {}
    for name in glob.glob(os.path.join(run, "particle_table_*.csv")):
        m = re.search(r"particle_table_(\d+)\.(\d+)\.csv$", name)
        by_counter.setdefault(int(m.group(1)), []).append((int(m.group(2)), name))
    return dict(sorted(by_counter.items()))


def read(name):
    with open(name) as f:
        header = f.readline().strip().split(",")
    data = np.loadtxt(name, delimiter=",", skiprows=1, ndmin=2)
    return {h: data[:, k] for k, h in enumerate(header)} if data.size else None


def main():
    run, interval = sys.argv[1], float(sys.argv[2])
    from_time = float(sys.argv[3]) if len(sys.argv) > 3 else None
    every = int(sys.argv[4]) if len(sys.argv) > 4 else 1
    rows = []
    for counter, pieces in tables(run).items():
        fastest, ranges = None, []
        for rank, name in sorted(pieces):
            t = read(name)
            if t is None:
                continue
            speed = np.hypot(t["velocity_x"], t["velocity_y"])
            i = int(np.argmax(speed))
            ranges.append(f"rank {rank} x {t['position_x'].min():.4f}-{t['position_x'].max():.4f}")
            if fastest is None or speed[i] > fastest[0]:
                fastest = (speed[i], int(t["id"][i]), t["position_x"][i], t["position_y"][i], rank)
        if fastest is not None:
            rows.append((counter * interval, fastest, "; ".join(ranges)))
    if not rows:
        sys.exit(f"float_runaway_where.py: no particle_table_*.csv with points in {run} "
                 "(Output/Write particle table = true?)")
    history = mpm_results.history(run)
    at_rest = history["time"] >= 0.5
    energy, times = history["kinetic_energy"][at_rest], history["time"][at_rest]
    start = None
    if len(energy):
        low = np.minimum.accumulate(energy)
        grown = np.nonzero(energy > 10 * low)[0]
        if len(grown):
            start = times[grown[0]]
            print(f"  kinetic energy tenfold its low ({low[grown[0]]:.3e} J) at t = {start:.4f} s")
    if from_time is None:
        from_time = start - interval if start is not None else 1.8
    for k, (time, f, ranges) in enumerate(row for row in rows if row[0] >= from_time - 1e-9):
        if k % every:
            continue
        print(f"  t {time:.2f}: fastest {f[0]:.3e} m/s, point {f[1]} at ({f[2]:.4f}, {f[3]:.4f}) on rank {f[4]}; {ranges}")


if __name__ == "__main__":
    main()
