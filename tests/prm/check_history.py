#!/usr/bin/python3
"""Asserts properties of a dealii-mpm time history (history.csv).
  --finite                    every value is finite
  --conserved COL[,COL...]    the columns stay equal to their first value (relative --rtol)
  --removed-at-least N        at least N points were removed (left the grid) by the end
  --none-removed              no point was removed (left the grid) on any row
  --energy-bounded            the kinetic energy never exceeds the work done by gravity (+1%; the
                              initial elastic energy of the scenes that use it is negligible)
  --at-rest F                 the final kinetic energy is below F times the work done by gravity
  --at-rest-after T,F         on every row from time T on, the kinetic energy is below F times the
                              work done by gravity (a settled heap that no burst of energy wakes)
  (with --removed-at-least, also: the mass left is that of the points left, and on every row
  the mass left and the removed mass make the initial mass, the run's own loss check)"""
import argparse
import os
import sys

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "..", "scripts"))
import mpm_results  # noqa: E402

parser = argparse.ArgumentParser()
parser.add_argument("output_dir")
parser.add_argument("--finite", action="store_true")
parser.add_argument("--conserved", default="")
parser.add_argument("--rtol", default="1e-12",
                    help="relative tolerance, or 'auto': n_points * 2.2e-16, the round-off bound of a sum over the points in any order")
parser.add_argument("--removed-at-least", type=int, default=0)
parser.add_argument("--none-removed", action="store_true")
parser.add_argument("--energy-bounded", action="store_true")
parser.add_argument("--at-rest", type=float)
parser.add_argument("--at-rest-after")
args = parser.parse_args()

if not os.path.isfile(os.path.join(args.output_dir, "history.csv")):
    sys.exit(f"FAILED: no history.csv in {args.output_dir} (did the run start?)")
h = mpm_results.history(args.output_dir)
failed = False
if args.finite:
    for key, values in h.items():
        if not np.all(np.isfinite(values)):
            print(f"FAILED: column {key} has non-finite values")
            failed = True
rtol = max(1e-14, h["n_points"][0] * 2.2e-16) if args.rtol == "auto" else float(args.rtol)
for key in filter(None, args.conserved.split(",")):
    values = h[key]
    scale = max(np.max(np.abs(values)), 1e-300)
    if key.startswith("momentum"):  # components may nearly cancel: compare with |p| ~ sqrt(2 M E_kin)
        scale = max(scale, np.max(np.sqrt(2 * h["total_mass"] * h["kinetic_energy"])))
    drift = np.max(np.abs(values - values[0])) / scale
    print(f"{key}: relative drift {drift:.3e} over {len(values)} rows (tolerance {rtol:.1e})")
    if not drift <= rtol:
        print(f"FAILED: {key} is not conserved")
        failed = True
if args.removed_at_least:
    removed = int(h["n_removed"][-1])
    print(f"points removed: {removed}, points left: {int(h['n_points'][-1])}")
    if removed < args.removed_at_least:
        print(f"FAILED: expected at least {args.removed_at_least} removed points")
        failed = True
    if int(h["n_points"][-1]) + removed != int(h["n_points"][0]):
        print("FAILED: points left + removed != points at the start")
        failed = True
    # equal point masses here: the mass left is that of the points left
    point_mass = h["total_mass"][0] / h["n_points"][0]
    if abs(h["total_mass"][-1] - point_mass * h["n_points"][-1]) > 1e-12 * h["total_mass"][0]:
        print("FAILED: the mass left does not match the points left")
        failed = True
    balance = (h["total_mass"] + h["removed_mass"] - h["total_mass"][0]) / h["total_mass"][0]
    print(f"mass left + removed mass - initial mass: at most {np.max(np.abs(balance)):.3e} of the initial mass"
          f" (the run's own column: {np.max(np.abs(h['mass_balance'])):.3e})")
    if not np.max(np.abs(balance)) <= 1e-12 or not np.max(np.abs(h["mass_balance"])) <= 1e-12:
        print("FAILED: mass lost or made")
        failed = True
if args.none_removed:
    removed = int(np.max(h["n_removed"]))
    print(f"points removed: {removed} (most on any row), points at the end: {int(h['n_points'][-1])} of "
          f"{int(h['n_points'][0])}")
    if removed != 0 or h["n_points"][-1] != h["n_points"][0]:
        print("FAILED: points were removed")
        failed = True
if args.energy_bounded:
    excess = np.max(h["kinetic_energy"] - 1.01 * np.maximum(h["work_of_gravity"], 0))
    print(f"max (kinetic energy - 1.01 work of gravity): {excess:.3e} J (must be <= 0)")
    if not excess <= 1e-12 * max(np.max(np.abs(h["work_of_gravity"])), 1e-300):
        print("FAILED: the kinetic energy exceeds the work done by gravity")
        failed = True
if args.at_rest is not None:
    ratio = h["kinetic_energy"][-1] / max(h["work_of_gravity"][-1], 1e-300)
    print(f"final kinetic energy / work of gravity: {ratio:.3e} (tolerance {args.at_rest:.1e})")
    if not ratio <= args.at_rest:
        print("FAILED: not at rest at the end")
        failed = True
if args.at_rest_after is not None:
    try:
        since, bound = (float(v) for v in args.at_rest_after.split(","))
    except ValueError:
        sys.exit(f"check_history.py: --at-rest-after takes T,F (two numbers), not '{args.at_rest_after}'")
    rows = h["time"] >= since
    if not np.any(rows):
        print(f"FAILED: --at-rest-after: no history row from t = {since} s on (the run ended at "
              f"{h['time'][-1]} s)")
        failed = True
    else:
        ratio = h["kinetic_energy"][rows] / np.maximum(h["work_of_gravity"][rows], 1e-300)
        worst = int(np.argmax(ratio))
        print(f"kinetic energy / work of gravity from t = {since} s: at most {ratio[worst]:.3e} at t = "
              f"{h['time'][rows][worst]:.4f} s (tolerance {bound:.1e}), {int(np.sum(rows))} rows")
        if not ratio[worst] <= bound:
            print("FAILED: the kinetic energy rose again after the heap had settled")
            failed = True
sys.exit(1 if failed else 0)
