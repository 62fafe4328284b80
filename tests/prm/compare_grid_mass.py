#!/usr/bin/python3
"""Grid/Nodes = near material writes only the cells with mass at a vertex: asserts that the last
grid output of a near-material run (NEAR_DIR) holds fewer vertices than that of Nodes = all
(ALL_DIR) and the same nodal masses and velocities at every vertex that has mass in either.
  compare_grid_mass.py ALL_DIR NEAR_DIR"""
import os
import sys

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "..", "scripts"))
import mpm_results  # noqa: E402


def vertices_with_mass(output_dir):
    """{vertex position (rounded): (mass, velocity...)} of the last grid output, and its number
    of vertex entries (each cell lists its own)."""
    _, pvtu = mpm_results.pvd_records(output_dir, "grid")[-1]
    data = mpm_results.read_pvtu(output_dir, pvtu)
    names = ["nodal_mass"] + sorted(k for k in data if k.startswith("nodal_velocity"))
    values = np.column_stack([data[k] for k in names])
    keys = [tuple(np.round(p, 9)) for p in data["position"]]
    return {k: tuple(v) for k, v in zip(keys, values) if v[0] != 0}, len(keys)


everywhere, n_all = vertices_with_mass(sys.argv[1])
near, n_near = vertices_with_mass(sys.argv[2])
if not n_near < n_all:
    sys.exit(f"FAILED: the near-material grid output has {n_near} vertex entries, Nodes = all {n_all}")
if everywhere != near:
    differ = len(set(everywhere.items()) ^ set(near.items()))
    sys.exit(f"FAILED: {differ} vertices with mass differ between the grid outputs")
print(f"grid output: {n_near} vertex entries instead of {n_all}; the {len(near)} vertices with mass agree")
