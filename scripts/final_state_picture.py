#!/usr/bin/python3
"""A picture of a run's last output, for a person without ParaView: the material points seen from the
side (x and the vertical axis; in 3D the points of all y), coloured by one of their fields.

Usage: final_state_picture.py OUTPUT_DIR OUT.png [--field NAME] [--time T]

--field: a particle field of the output (stress_xx, plastic_strain, ...; default: the vertical stress,
stress_yy in 2D and stress_zz in 3D) or 'displacement' (distance from the initial position).
--time: the output nearest to T (default: the last).
"""
import argparse
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import mpm_results  # noqa: E402


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("output_dir")
    ap.add_argument("png")
    ap.add_argument("--field")
    ap.add_argument("--time", type=float)
    args = ap.parse_args()

    records = mpm_results.pvd_records(args.output_dir)
    index = -1 if args.time is None else int(np.argmin([abs(t - args.time) for t, _ in records]))
    data = mpm_results.particles_at(args.output_dir, index)
    x = data["position"]
    three_d = bool(np.any(x[:, 2]))
    vertical = 2 if three_d else 1
    field = args.field or ("stress_zz" if three_d else "stress_yy")
    if field == "displacement":
        values, label = np.linalg.norm(x - data["initial_position"], axis=1), "displacement (m)"
    elif field in data:
        values = data[field]
        label = field + (" (Pa)" if field.startswith("stress") else "")
    else:
        sys.exit(f"no field '{field}' in the output; fields: displacement, " +
                 ", ".join(k for k, v in data.items() if isinstance(v, np.ndarray) and v.ndim == 1))

    extent = np.ptp(x[:, [0, vertical]], axis=0) + 1e-12
    ratio = extent[1] / extent[0]
    # True proportions unless the scene is very slender (the V1 column is 1 cell wide): then stretched.
    to_scale = 0.2 < ratio < 5
    width = 7.0
    height = min(9.0, max(2.5, width * ratio + 1.0)) if to_scale else 5.0
    fig, ax = plt.subplots(figsize=(width, height))
    size = max(2.0, 4000.0 / len(values))
    points = ax.scatter(x[:, 0], x[:, vertical], c=values, s=size, cmap="viridis", linewidths=0)
    fig.colorbar(points, ax=ax, label=label)
    if to_scale:
        ax.set_aspect("equal")
    ax.set_xlabel("x (m)" + ("" if to_scale else ", stretched"))
    ax.set_ylabel(("z" if three_d else "y") + " (m)")
    ax.set_title(f"t = {data['time']:.4g} s, {len(values)} material points", fontsize=10)
    fig.tight_layout()
    fig.savefig(args.png, dpi=120)
    print(f"picture of the final state: {os.path.abspath(args.png)}")


if __name__ == "__main__":
    main()
