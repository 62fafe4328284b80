#!/usr/bin/python3
"""Table and plot of a V6 sweep (scripts/validation/v6_sweep.sh's RESULTS, one JSON line per run).

Usage: v6_report.py RESULTS [--png FILE] [--csv FILE]
Prints a Markdown table (run-out, error against the fit, wall time per run); --png draws the
normalised run-out against lambda0 with the experiments' fit 0.63 lambda0^1.30; --csv keeps the
numbers without the thickness profiles. Needs Debian's python3-matplotlib for --png.
"""
import argparse
import csv
import json

FIELDS = ["lambda", "cells", "base", "damping", "runout", "fit", "error", "r_inf", "spread", "height", "n_points",
          "n_steps", "wall", "program_seconds", "kinetic_energy_end", "work_of_gravity", "n_removed"]


def load(path):
    runs = [json.loads(line) for line in open(path) if line.strip()]
    bad = [r["tag"] for r in runs if r.get("rc", 0) != 0]
    if bad:
        raise SystemExit(f"v6_report.py: runs that failed: {bad}")
    return sorted(runs, key=lambda r: (r["lambda"], r["cells"], r["base"], r["damping"]))


def table(runs):
    lines = ["| lambda0 | cells / r0 | base | D | (r_inf - r0)/r0 | fit | error | h_inf (m) | points | steps | "
             "wall (s) |", "|---|---|---|---|---|---|---|---|---|---|---|"]
    for r in runs:
        lines.append(f"| {r['lambda']:g} | {r['cells']} | {r['base']} | {r['damping']:g} | {r['runout']:.3f} | "
                     f"{r['fit']:.3f} | {100 * r['error']:+.1f}% | {r['height']:.3f} | {r['n_points']:,} | "
                     f"{r['n_steps']:,} | {r['wall']:.1f} |")
    return "\n".join(lines)


def plot(runs, png):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import numpy as np

    fig, ax = plt.subplots(figsize=(7, 5))
    lam = np.geomspace(0.4, 10, 100)
    ax.plot(lam, 0.63 * lam ** 1.30, "k-", label="experiments' fit 0.63 $\\lambda_0^{1.30}$ (Wyser 2022)")
    ax.fill_between(lam, 0.85 * 0.63 * lam ** 1.30, 1.15 * 0.63 * lam ** 1.30, color="0.85", label="fit $\\pm$ 15%")
    colours = {0.0: "C3", 0.025: "C1", 0.05: "C2", 0.1: "C0"}
    for base, marker in (("friction", "o"), ("no-slip", "s")):
        for damping, colour in colours.items():
            sel = [r for r in runs if r["base"] == base and r["damping"] == damping]
            if not sel:
                continue
            shift = 1 + 0.03 * (list(colours).index(damping) - 1.5)  # side by side at each lambda0
            ax.plot([r["lambda"] * shift for r in sel], [r["runout"] for r in sel], marker, color=colour,
                    mfc=colour if base == "friction" else "none", ls="none",
                    label=f"{base}, D = {damping:g}")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("aspect ratio $\\lambda_0 = h_0 / r_0$")
    ax.set_ylabel("normalised run-out $(r_\\infty - r_0) / r_0$")
    ax.set_title("V6 quarter columns on the H100 (20 cells per $r_0$; $\\lambda_0$ = 8: 10)")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=7, ncol=2, loc="upper left")
    fig.tight_layout()
    fig.savefig(png, dpi=120)


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("results")
    parser.add_argument("--png", default=None)
    parser.add_argument("--csv", default=None)
    args = parser.parse_args()
    runs = load(args.results)
    print(table(runs))
    if args.csv:
        with open(args.csv, "w", newline="") as f:
            writer = csv.DictWriter(f, fieldnames=FIELDS, extrasaction="ignore")
            writer.writeheader()
            writer.writerows(runs)
    if args.png:
        plot(runs, args.png)


if __name__ == "__main__":
    main()
