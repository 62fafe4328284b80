#!/usr/bin/python3
"""Asserts the physics of tests/prm/prefailure/end_to_end.sh's two runs of V7 (OUT/failing,
OUT/stable, and their logs):
  - the strength reduction's factor of safety within 5% of Griffiths & Lane's 1.4 at this
    coarse mesh (doc/prefailure.md has the mesh convergence);
  - the hand-over carries the body's whole mass: rho x the slope's area (300 m2) to 1e-12;
  - at F = 1 the handed-over state is in equilibrium: the MPM stays at rest, its kinetic
    energy below 1e-6 of M g H;
  - with the strengths divided by 2 the slope fails: the toe advances more than 1 m (one MPM cell) within
    4 s, and the peak kinetic energy exceeds 1000 times that of the stable run."""
import os
import re
import sys

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "..", "..", "scripts"))
import mpm_results  # noqa: E402

out = sys.argv[1]
rho, area, g, H = 2038.7359836901, 300.0, 9.81, 10.0
failed = False


def check(ok, what):
    global failed
    print(("  ok    " if ok else "  FAIL  ") + what)
    failed = failed or not ok


log = open(os.path.join(out, "failing.log")).read()
match = re.search(r"factor of safety F = ([0-9.]+)", log)
F = float(match.group(1)) if match else float("nan")
check(abs(F - 1.4) / 1.4 < 0.05, f"factor of safety {F:.4f}, Griffiths & Lane 1.4 (within 5% at 2 m cells)")

runs = {name: mpm_results.history(os.path.join(out, name)) for name in ("failing", "stable")}
for name, h in runs.items():
    mass = h["total_mass"][0]
    check(abs(mass - rho * area) <= 1e-12 * rho * area,
          f"{name}: mass handed over {mass:.6f} kg, rho x area {rho * area:.6f} kg")
MgH = rho * area * g * H
stable_peak = np.max(runs["stable"]["kinetic_energy"])
check(stable_peak < 1e-6 * MgH, f"stable (F = 1): peak kinetic energy {stable_peak:.3e} J < 1e-6 M g H = {1e-6 * MgH:.3e} J")
h = runs["failing"]
advance = h["max_x"][-1] - h["max_x"][0]
failing_peak = np.max(h["kinetic_energy"])
check(advance > 1.0, f"failing (strengths / 2): the toe advances {advance:.3f} m in {h['time'][-1]:.2f} s (> 1 m)")
check(failing_peak > 1e3 * stable_peak,
      f"failing: peak kinetic energy {failing_peak:.3e} J, {failing_peak / max(stable_peak, 1e-300):.3e} times the stable run's (> 1000)")
sys.exit(1 if failed else 0)
