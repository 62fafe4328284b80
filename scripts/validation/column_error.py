#!/usr/bin/python3
"""V1 elastic column: error norm of the final vertical stress against the analytic
sigma_yy(y0) = -rho g (l0 - y0), e = sum_p |sigma_yy,p - exact| V0_p / (rho g l0 V0).

With --law, also the points' heights against the large-strain solution of that elastic law
(uniaxial strain, Poisson's ratio 0, Young's modulus --E): the stretch s(y0) solves
sigma = E ln s (Jaumann rate) or sigma = E ln(s) / s (Hencky: Kirchhoff stress J sigma = E ln s,
J = s), and a point's height is the integral of s from the base. The error is
sum_p |y_p - y(y0_p)| V0_p / (V0 |y(l0) - l0|), the mean height error over the top's settlement.

Usage: column_error.py OUTPUT_DIR [--rho 80] [--g 9.81] [--l0 10] [--max-error E]
                      [--law jaumann|hencky --E 1e4 --max-height-error E]
Prints the errors; exits 1 if one exceeds its maximum."""
import argparse
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))  # scripts/: mpm_results
import mpm_results  # noqa: E402


def column_error(output_dir, rho=80.0, g=9.81, l0=10.0, axis=None):
    p = mpm_results.particles_at(output_dir)
    if axis is None:  # vertical: the last axis the points use (y in 2D, z in 3D)
        axis = 2 if np.any(p["initial_position"][:, 2] != 0) else 1
    y0 = p["initial_position"][:, axis]
    v0 = p["initial_volume"]
    exact = -rho * g * (l0 - y0)
    stress = p["stress_zz" if axis == 2 else "stress_yy"]
    return float(np.sum(np.abs(stress - exact) * v0) / (rho * g * l0 * np.sum(v0))), p


def exact_heights(y0, law, E, rho=80.0, g=9.81, l0=10.0, n=20000):
    """Heights of material at y0 in the deformed column under the given elastic law."""
    Y = np.linspace(0.0, l0, n + 1)
    sigma = -rho * g * (l0 - Y)
    if law == "jaumann":
        s = np.exp(sigma / E)
    else:  # E ln(s) / s = sigma, increasing in s on (0, 1]: bisection
        lo, hi = np.full_like(Y, 1e-6), np.ones_like(Y)
        for _ in range(100):
            mid = 0.5 * (lo + hi)
            low = E * np.log(mid) / mid < sigma
            lo, hi = np.where(low, mid, lo), np.where(low, hi, mid)
        s = 0.5 * (lo + hi)
    y = np.concatenate([[0.0], np.cumsum(0.5 * (s[1:] + s[:-1]) * np.diff(Y))])
    return np.interp(y0, Y, y), y[-1]


def height_error(p, law, E, rho=80.0, g=9.81, l0=10.0):
    axis = 2 if np.any(p["initial_position"][:, 2] != 0) else 1
    y0, v0 = p["initial_position"][:, axis], p["initial_volume"]
    exact, top = exact_heights(y0, law, E, rho, g, l0)
    return float(np.sum(np.abs(p["position"][:, axis] - exact) * v0) / (np.sum(v0) * abs(top - l0))), top


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("output_dir")
    parser.add_argument("--rho", type=float, default=80.0)
    parser.add_argument("--g", type=float, default=9.81)
    parser.add_argument("--l0", type=float, default=10.0)
    parser.add_argument("--max-error", type=float, default=None)
    parser.add_argument("--law", choices=["jaumann", "hencky"])
    parser.add_argument("--E", type=float, default=1e4, help="Young's modulus (Pa)")
    parser.add_argument("--max-height-error", type=float, default=None)
    parser.add_argument("--like", default=None, help="another run's output folder: the error norm must be within "
                        "--within (relative) of that run's")
    parser.add_argument("--within", type=float, default=0.05)
    args = parser.parse_args()
    error, p = column_error(args.output_dir, args.rho, args.g, args.l0)
    print(f"V1 column: {len(p['mass'])} points at t = {p['time']:.4g} s, error norm {error:.4e}")
    failed = args.max_error is not None and not error <= args.max_error
    if failed:
        print(f"FAILED: error {error:.4e} exceeds {args.max_error:.4e}")
    if args.law:
        h_error, top = height_error(p, args.law, args.E, args.rho, args.g, args.l0)
        print(f"heights against the {args.law} solution (top at {top:.4f} m): error {h_error:.4e}")
        if args.max_height_error is not None and not h_error <= args.max_height_error:
            print(f"FAILED: height error {h_error:.4e} exceeds {args.max_height_error:.4e}")
            failed = True
    if args.like:
        other, _ = column_error(args.like, args.rho, args.g, args.l0)
        relative = abs(error - other) / other
        print(f"against {args.like}: error norm {other:.4e}, relative difference {relative:.3g} "
              f"(at most {args.within:.3g})")
        if not relative <= args.within:
            print(f"FAILED: the error norms differ by {relative:.3g} of {other:.4e}")
            failed = True
    sys.exit(1 if failed else 0)
