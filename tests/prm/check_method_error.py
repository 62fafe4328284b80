#!/usr/bin/env python3
"""A run of Solver/Method = auto against its promise: the study's error measure of the scene kind
(scripts/validation/study.py) on the run's output is at most the tolerance, and the log names the pick.
Usage: check_method_error.py OUTDIR LOG SCENE TOLERANCE     (SCENE: v3; the other kinds need the study's
reference runs)"""
import os
import sys

here = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(here, "..", "..", "scripts", "validation"))
import study  # noqa: E402

out, log, scene, tolerance = sys.argv[1], sys.argv[2], sys.argv[3], float(sys.argv[4])
text = open(log).read()
picked = [line.strip() for line in text.splitlines() if line.strip().startswith("picked ")]
if "Method = auto" not in text or not picked:
    sys.exit(f"FAILED: the log does not say what Method = auto picked ({log})")
errors = {"v3": study.v3_error}
error, details = errors[scene](out)
print(f"{picked[0]}\nmeasured: error {error:.4g} ({details}); tolerance {tolerance:g}")
if not error <= tolerance:
    sys.exit(f"FAILED: the run's error {error:.4g} is above the tolerance {tolerance:g} that Method = auto promised")
print("ok")
