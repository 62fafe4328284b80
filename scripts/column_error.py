#!/usr/bin/python3
"""V1 elastic column: error norm of the final vertical stress against the analytic
sigma_yy(y0) = -rho g (l0 - y0), e = sum_p |sigma_yy,p - exact| V0_p / (rho g l0 V0).
Usage: column_error.py OUTPUT_DIR [--rho 80] [--g 9.81] [--l0 10] [--max-error E]
Prints the error; exits 1 if it exceeds --max-error."""
import argparse
import sys

import numpy as np

sys.path.insert(0, __import__("os").path.dirname(__file__))
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


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("output_dir")
    parser.add_argument("--rho", type=float, default=80.0)
    parser.add_argument("--g", type=float, default=9.81)
    parser.add_argument("--l0", type=float, default=10.0)
    parser.add_argument("--max-error", type=float, default=None)
    args = parser.parse_args()
    error, p = column_error(args.output_dir, args.rho, args.g, args.l0)
    print(f"V1 column: {len(p['mass'])} points at t = {p['time']:.4g} s, error norm {error:.4e}")
    if args.max_error is not None and not error <= args.max_error:
        print(f"FAILED: error {error:.4e} exceeds {args.max_error:.4e}")
        sys.exit(1)
