#!/usr/bin/python3
"""Pictures of a pre-failure analysis and the MPM run that follows it (doc/prefailure.md).

Usage: prefailure_picture.py OUTPUT_DIR OUT.png [--scale S]

Left: the FEM's failure mechanism (prefailure_failure_mechanism_0.pvtu: the state at the
factor of safety), the mesh deformed by S times its displacement, coloured by the plastic strain.
Right: the MPM's material points at the last output, coloured by their plastic strain.
2D runs only.
"""
import argparse
import glob
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import meshio  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.collections import PolyCollection  # noqa: E402

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import mpm_results  # noqa: E402


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("output_dir")
    ap.add_argument("png")
    ap.add_argument("--scale", type=float, default=50.0)
    args = ap.parse_args()

    pieces = sorted(glob.glob(os.path.join(args.output_dir, "prefailure_failure_mechanism_0.*.vtu")))
    fig, (left, right) = plt.subplots(1, 2, figsize=(13, 3.8))
    polygons, values = [], []
    for piece in pieces:
        mesh = meshio.read(piece)
        x = mesh.points[:, :2] + args.scale * mesh.point_data["displacement"][:, :2]
        for cell in mesh.cells_dict["quad"]:  # VTK order: counter-clockwise
            polygons.append(x[cell])
        values.extend(mesh.point_data["plastic_strain"][mesh.cells_dict["quad"]].mean(axis=1))
    collection = PolyCollection(polygons, array=np.array(values), cmap="viridis", edgecolors="none")
    left.add_collection(collection)
    left.autoscale()
    left.set_aspect("equal")
    fig.colorbar(collection, ax=left, label="plastic strain", shrink=0.8)
    left.set_title(f"FEM at the factor of safety (displacement x {args.scale:g})")

    points = mpm_results.particles_at(args.output_dir)
    xy = points["position"][:, :2]
    scatter = right.scatter(xy[:, 0], xy[:, 1], c=points["plastic_strain"], s=2, cmap="magma")
    right.set_aspect("equal")
    fig.colorbar(scatter, ax=right, label="plastic strain", shrink=0.8)
    right.set_title(f"MPM run-out, t = {points['time']:g} s")
    for ax in (left, right):
        ax.set_xlabel("x [m]")
        ax.set_ylabel("y [m]")
    fig.tight_layout()
    fig.savefig(args.png, dpi=110)
    print("wrote", args.png)


if __name__ == "__main__":
    main()
