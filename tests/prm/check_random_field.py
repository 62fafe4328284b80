#!/usr/bin/python3
"""Checks the random field the points of a run carry (property material_field): mean,
standard deviation and the correlation at lag L along x against a Gaussian covariance
exp(-(r/L)^2). Usage: check_random_field.py OUTPUT_DIR MEAN STD L
Tolerances from the sampling error of a domain holding N ~ area / L^2 independent patches:
mean 4 s/sqrt(N), standard deviation 10%, correlation 0.12 (about 3.5/sqrt(N))."""
import os
import sys

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "..", "scripts"))
import mpm_results  # noqa: E402

out, mean, std, L = sys.argv[1], float(sys.argv[2]), float(sys.argv[3]), float(sys.argv[4])
p = mpm_results.particles_at(out, 0)
x, y, v = p["initial_position"][:, 0], p["initial_position"][:, 1], p["material_field"]
xs, ys = np.unique(np.round(x, 9)), np.unique(np.round(y, 9))
grid = np.full((len(ys), len(xs)), np.nan)
grid[np.searchsorted(ys, np.round(y, 9)), np.searchsorted(xs, np.round(x, 9))] = v
n_patches = (xs[-1] - xs[0]) * (ys[-1] - ys[0]) / L**2
lag = int(round(L / (xs[1] - xs[0])))
a = grid - v.mean()
corr = np.nanmean(a[:, :-lag] * a[:, lag:]) / v.var()
print(f"{len(v)} points: mean {v.mean():.1f} (expect {mean}), std {v.std():.1f} (expect {std}), "
      f"correlation at lag L {corr:.3f} (expect {np.exp(-1):.3f}), ~{n_patches:.0f} patches")
ok = abs(v.mean() - mean) <= 4 * std / np.sqrt(n_patches) and abs(v.std() / std - 1) <= 0.10 \
    and abs(corr - np.exp(-1)) <= 0.12 and not np.isnan(grid).any()
print("ok" if ok else "FAILED")
sys.exit(0 if ok else 1)
