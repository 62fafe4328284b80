#!/usr/bin/python3
"""Compare the last particle outputs of two dealii-mpm runs of the same prm (e.g. Backend = cpu
and cuda): points are matched by their initial position, then the script prints the largest and
RMS difference of the positions, velocities and stresses, and per run the toe (largest x + l_x,
wall at x = 0) and height (largest vertical coordinate + its half-length) of the deposit.

Usage: compare_backends.py OUTPUT_DIR_A OUTPUT_DIR_B   (needs python3-numpy and python3-meshio)
"""
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import mpm_results  # noqa: E402


def load(directory):
    d = mpm_results.particles_at(directory)
    x0 = np.asarray(d["initial_position"])
    order = np.lexsort(x0.T[::-1])
    return d, order


def main():
    a, ia = load(sys.argv[1])
    b, ib = load(sys.argv[2])
    if len(ia) != len(ib):
        # points removed in one run only (left the grid): compare the points both still have
        ka = {tuple(np.round(x, 9)): k for k, x in zip(ia, a["initial_position"][ia])}
        kb = {tuple(np.round(x, 9)): k for k, x in zip(ib, b["initial_position"][ib])}
        common = sorted(set(ka) & set(kb))
        print(f"point counts differ: {len(ia)} and {len(ib)}; comparing the {len(common)} points both have")
        ia = np.array([ka[c] for c in common])
        ib = np.array([kb[c] for c in common])
    x0a, x0b = a["initial_position"][ia], b["initial_position"][ib]
    assert np.allclose(x0a, x0b, rtol=0, atol=1e-9), "initial positions do not match"
    dim = x0a.shape[1]
    xa, xb = a["position"][ia, :dim], b["position"][ib, :dim]
    dx = np.linalg.norm(xa - xb, axis=1)
    va, vb = a["velocity"][ia], b["velocity"][ib]
    dv = np.linalg.norm(va - vb, axis=1)
    names = ["stress_xx", "stress_yy", "stress_zz", "stress_xy", "stress_yz", "stress_xz"]
    sa = np.stack([a[n][ia] for n in names], axis=1)
    sb = np.stack([b[n][ib] for n in names], axis=1)
    s_scale = np.abs(sa).max()
    print(f"time {a['time']} / {b['time']} s, {len(ia)} points")
    print(f"position difference: max {1e3 * dx.max():.4g} mm, RMS {1e3 * np.sqrt((dx ** 2).mean()):.4g} mm")
    print(f"velocity difference: max {dv.max():.4g} m/s (max |v| {np.linalg.norm(va, axis=1).max():.4g} m/s)")
    print(f"stress difference: max {np.abs(sa - sb).max():.4g} Pa (max |sigma| {s_scale:.4g} Pa)")
    for name, d, idx in (("A", a, ia), ("B", b, ib)):
        x = d["position"][idx, :dim]
        l = d["domain_half_length"][idx]
        toe = (x[:, 0] + l[:, 0]).max()
        height = (x[:, dim - 1] + l[:, dim - 1]).max()
        print(f"{name}: toe {1e3 * toe:.2f} mm, height {1e3 * height:.2f} mm")
    return 0


if __name__ == "__main__":
    sys.exit(main())
