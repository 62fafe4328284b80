#!/usr/bin/python3
"""Draw the F-displacement curve of a strength reduction (dealii-mpm, Pre-failure analysis).

Usage: strength_reduction_plot.py OUTPUT_DIR [--png FILE] [--label TEXT] [more OUTPUT_DIRs ...]

Reads OUTPUT_DIR/strength_reduction.csv (one row per factor tried) and plots the monitor
point's displacement against F for the converged factors, with the failing factors marked on
the axis and the factor of safety (the last converged F) in the legend. Several directories
draw several curves (e.g. meshes or dilatancy angles). Default PNG:
OUTPUT_DIR/strength_reduction.png of the first directory.
"""
import argparse
import csv
import os

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt


def read(directory):
    with open(os.path.join(directory, "strength_reduction.csv")) as f:
        rows = list(csv.DictReader(f))
    converged = sorted((float(r["factor"]), float(r["monitor_displacement"])) for r in rows if r["converged"] == "1")
    failed = sorted(float(r["factor"]) for r in rows if r["converged"] == "0")
    return converged, failed


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("directories", nargs="+")
    parser.add_argument("--png")
    parser.add_argument("--label", action="append", help="one per directory (default: the directory name)")
    args = parser.parse_args()
    labels = args.label or [os.path.basename(os.path.normpath(d)) for d in args.directories]
    if len(labels) != len(args.directories):
        parser.error("give one --label per directory")

    fig, ax = plt.subplots(figsize=(6.4, 4.2))
    for directory, label in zip(args.directories, labels):
        converged, failed = read(directory)
        F = [c[0] for c in converged]
        u = [1000 * c[1] for c in converged]
        fos = max(F)
        line, = ax.plot(F, u, "o-", ms=3, label=f"{label}: F = {fos:.3f}")
        above = [x for x in failed if x > fos]
        if above:
            ax.axvline(min(above), color=line.get_color(), ls=":", lw=1)
        print(f"{directory}: factor of safety {fos:.4f}, lowest failing factor "
              f"{min(above) if above else float('inf'):.4f}, monitor displacement at F: {u[F.index(fos)]:.3f} mm")
    ax.set_xlabel("strength reduction factor F")
    ax.set_ylabel("monitor point displacement since F = 1 [mm]")
    ax.set_title("Strength reduction (dotted: first failing factor)")
    ax.grid(alpha=0.3)
    ax.legend()
    png = args.png or os.path.join(args.directories[0], "strength_reduction.png")
    fig.tight_layout()
    fig.savefig(png, dpi=120)
    print("wrote", png)


if __name__ == "__main__":
    main()
