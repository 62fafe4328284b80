#!/usr/bin/python3
"""Is a slope scene in equilibrium? Horizontal thrust through vertical sections and the stress
ratio s_xx / s_zz behind the slope, from dealii-mpm output or from ep2-3De point tables.

Usage: slump_equilibrium.py RUN [RUN ...] [--time T] [options] [checks]

A RUN is [LABEL=]PATH[@T]: an output folder of dealii-mpm (the output nearest to T, default --time)
or a table of points as in ../shared/reference/ep23de-v5-homogeneous (.csv or .csv.gz: x, y, z, s_xx,
s_yy, s_zz, ...; its T is ignored). x is horizontal, the last coordinate vertical; 3D or 2D.

Thrust. On a base that carries no shear (free-slip) a body at rest in static equilibrium carries the
same horizontal force through every vertical section: the thrust T(x) = integral of s_xx dz over the
height of the section, per metre of width (N/m). It is measured from the points without their volumes
(ep2-3De's tables have none): the points within --slab / 2 of x, binned in z by --dz, the mean s_xx
of each bin that holds points times --dz, summed. The spread is max |T(x) - median T| / |median T|
over the sections --sections FIRST:LAST:STEP (default 1:63:2 m).

Stress ratio. Behind the slope (x < --behind, default 8 m), the points binned in z by --bin (default
0.80198 m, one cell of V5): sum s_xx / sum s_zz per bin (compression negative; the ratio is K0 where
the ground is laterally confined).

Checks on the first RUN (exit status 1 if one fails):
  --reference RUN --ratio-tolerance R  every depth bin's ratio within R (relative) of the reference's
                                      in the same bin; every bin but the one at the surface (where
                                      s_zz tends to zero, and the ratio is ill-conditioned) must be
                                      present in both;
  --thrust-spread S                   the thrust spread at most S (equilibrium);
  --thrust-spread-above S             the thrust spread above S (not in equilibrium).
--plot FILE draws T(x) of every RUN (matplotlib).
"""
import argparse
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))  # scripts/: mpm_results
import mpm_results  # noqa: E402

V5_CELL = 64.1584 / 80


class Run:
    def __init__(self, spec, default_time):
        label, _, rest = spec.rpartition("=")
        path, _, t = rest.partition("@")
        self.label = label or path
        self.path = path
        if os.path.isdir(path):
            records = mpm_results.pvd_records(path)
            time = float(t) if t else default_time
            index = int(np.argmin([abs(rt - time) for rt, _ in records]))
            data = mpm_results.particles_at(path, index)
            self.time = data["time"]
            x = data["position"]
            if not np.any(x[:, 2]):
                x = x[:, :2]  # 2D output, written with z = 0
            self.x = x
            self.s_xx = data["stress_xx"]
            self.s_zz = data["stress_zz"] if x.shape[1] == 3 else data["stress_yy"]
        else:
            table = np.loadtxt(path, delimiter=",", skiprows=1)
            self.time = float(t) if t else float("nan")
            self.x, self.s_xx, self.s_zz = table[:, :3], table[:, 3], table[:, 5]
        self.z = self.x[:, -1]

    def thrust(self, sections, slab, dz):
        result = []
        for xc in sections:
            near = np.abs(self.x[:, 0] - xc) < slab / 2
            bins = np.floor(self.z[near] / dz).astype(int)
            s = self.s_xx[near]
            result.append(sum(s[bins == b].mean() * dz for b in np.unique(bins)))
        return np.array(result)

    def ratios(self, behind, bin_height):
        """{bin index: (bin centre, s_xx / s_zz, number of points)} for x < behind."""
        back = self.x[:, 0] < behind
        bins = np.floor(self.z[back] / bin_height).astype(int)
        sx, sz = self.s_xx[back], self.s_zz[back]
        return {int(b): ((b + 0.5) * bin_height, sx[bins == b].sum() / sz[bins == b].sum(), int((bins == b).sum()))
                for b in np.unique(bins)}


def spread(thrust):
    median = np.median(thrust)
    return float(np.max(np.abs(thrust - median)) / abs(median))


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("runs", nargs="+")
    ap.add_argument("--time", type=float, default=8.0)
    ap.add_argument("--sections", default="1:63:2", help="FIRST:LAST:STEP (m)")
    ap.add_argument("--slab", type=float, default=V5_CELL, help="width of a section's slab (m)")
    ap.add_argument("--dz", type=float, default=V5_CELL / 2, help="height of the thrust's z bins (m)")
    ap.add_argument("--behind", type=float, default=8.0)
    ap.add_argument("--bin", type=float, default=V5_CELL)
    ap.add_argument("--reference")
    ap.add_argument("--ratio-tolerance", type=float)
    ap.add_argument("--thrust-spread", type=float)
    ap.add_argument("--thrust-spread-above", type=float)
    ap.add_argument("--plot")
    args = ap.parse_args()

    first, last, step = (float(v) for v in args.sections.split(":"))
    sections = np.arange(first, last + step / 2, step)
    runs = [Run(spec, args.time) for spec in args.runs]
    thrusts = []
    for run in runs:
        thrust = run.thrust(sections, args.slab, args.dz)
        thrusts.append(thrust)
        print(f"{run.label} (t = {run.time:g} s): thrust (kN/m) at x = {sections[0]:g}..{sections[-1]:g} m:")
        print("  " + " ".join(f"{v / 1e3:.0f}" for v in thrust))
        print(f"  spread {spread(thrust):.3f} (max |T - median| / |median|, median {np.median(thrust) / 1e3:.1f} kN/m)")
        print(f"  s_xx / s_zz at x < {args.behind:g} m, per {args.bin:g} m of height (z, ratio, points): " +
              "; ".join(f"{z:.1f} {r:.3f} {n}" for z, r, n in run.ratios(args.behind, args.bin).values()))

    failed = False
    ours = runs[0]
    if args.reference is not None and args.ratio_tolerance is not None:
        reference = Run(args.reference, args.time)
        mine, theirs = ours.ratios(args.behind, args.bin), reference.ratios(args.behind, args.bin)
        # The bin at the surface is left out: s_zz tends to zero there and the ratio with it.
        common = sorted((set(mine) & set(theirs)) - {max(mine), max(theirs)})
        worst, where = 0.0, None
        for b in common:
            deviation = abs(mine[b][1] - theirs[b][1]) / abs(theirs[b][1])
            if deviation >= worst:
                worst, where = deviation, mine[b][0]
        top = max(mine)
        print(f"  s_xx / s_zz against {reference.label}: {len(common)} bins below the surface in common (of "
              f"{len(mine)} and {len(theirs)}), largest relative difference {worst:.3f} at z = {where:.1f} m; "
              f"surface bin (not checked): {mine[top][1]:.3f} against "
              f"{theirs[top][1] if top in theirs else float('nan'):.3f}")
        failed |= mpm_results.check_limits([("ratio difference", worst, (0.0, args.ratio_tolerance))])
        # Every bin but the surface one is compared (the two columns have the same height).
        failed |= mpm_results.check_limits([("bins compared", len(common), (max(len(mine), len(theirs)) - 1, 1e9))])
    if args.thrust_spread is not None:
        failed |= mpm_results.check_limits([("thrust spread", spread(thrusts[0]), (0.0, args.thrust_spread))])
    if args.thrust_spread_above is not None:
        failed |= mpm_results.check_limits([("thrust spread", spread(thrusts[0]), (args.thrust_spread_above, 1e9))])

    if args.plot:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        fig, ax = plt.subplots(figsize=(7, 3.6))
        for run, thrust in zip(runs, thrusts):
            ax.plot(sections, thrust / 1e3, marker=".", label=run.label)
        ax.set_xlabel("x of the vertical section (m)")
        ax.set_ylabel("thrust: integral of s_xx dz (kN/m)")
        ax.axhline(0, color="0.7", lw=0.5)
        ax.legend(fontsize=8)
        fig.tight_layout()
        fig.savefig(args.plot, dpi=130)
        print(f"wrote {args.plot}")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
