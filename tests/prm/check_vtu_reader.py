#!/usr/bin/python3
"""scripts/mpm_results.read_vtu (numpy alone, for hosts without meshio) against meshio on every
.vtu piece of the last particle and grid outputs of OUTPUT_DIR: the same points and point data,
bit for bit. Exit status 1 on a difference."""
import os
import sys

import meshio
import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "scripts"))
import mpm_results  # noqa: E402

output_dir = sys.argv[1]
failed, compared = False, 0
for name in ("particles", "grid"):
    records = mpm_results.pvd_records(output_dir, name)
    if not records:
        continue
    pvtu = os.path.join(output_dir, records[-1][1])
    for piece in sorted(f for f in os.listdir(output_dir) if f.startswith(os.path.basename(pvtu)[:-5] + ".")):
        if not piece.endswith(".vtu"):
            continue
        path = os.path.join(output_dir, piece)
        points, data = mpm_results.read_vtu(path)
        reference = meshio.read(path)
        same = np.array_equal(points, reference.points) and set(data) == set(reference.point_data)
        same = same and all(np.array_equal(np.asarray(data[k]), np.asarray(reference.point_data[k])) for k in data)
        print(f"  {piece}: {len(points)} points, {len(data)} arrays: {'same' if same else 'DIFFERENT'}")
        failed |= not same
        compared += 1
if compared == 0:
    print("no .vtu pieces found")
sys.exit(1 if failed or compared == 0 else 0)
