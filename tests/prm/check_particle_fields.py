#!/usr/bin/python3
"""Output/Particle fields: ALL_DIR and SELECTED_DIR hold the same run with every field and with the
fields FIELDS (comma-separated). At every output, SELECTED_DIR's particle .vtu pieces must hold
the id and exactly the arrays of those fields, with the values of ALL_DIR's (bit for bit: the same
run on the CPU), and take fewer bytes. numpy alone (scripts/mpm_results.read_vtu)."""
import os
import sys

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "scripts"))
import mpm_results  # noqa: E402

all_dir, selected_dir, fields = sys.argv[1], sys.argv[2], set(sys.argv[3].split(","))


def field_of(array):
    """The Output/Particle fields name of a .vtu array: stress_xx -> stress, F_xy -> F."""
    for group in ("stress", "strain", "F"):
        if array.startswith(group + "_"):
            return group
    return array


records_all = mpm_results.pvd_records(all_dir)
records_selected = mpm_results.pvd_records(selected_dir)
if len(records_all) < 2 or [t for t, _ in records_all] != [t for t, _ in records_selected]:
    sys.exit(f"FAILED: the two runs' outputs differ or are too few: {records_all} / {records_selected}")
bytes_all = bytes_selected = 0
for (time, pvtu), (_, pvtu_selected) in zip(records_all, records_selected):
    stem = os.path.basename(pvtu)[:-5]
    pieces = sorted(f for f in os.listdir(all_dir) if f.startswith(stem + ".") and f.endswith(".vtu"))
    for piece in pieces:
        points, data = mpm_results.read_vtu(os.path.join(all_dir, piece))
        points_s, data_s = mpm_results.read_vtu(os.path.join(selected_dir, piece))
        expected = {"id"} | {name for name in data if field_of(name) in fields}
        if set(data_s) != expected:
            sys.exit(f"FAILED: {piece} at t = {time} holds {sorted(data_s)}, expected {sorted(expected)}")
        if not np.array_equal(points, points_s) or any(not np.array_equal(data[k], data_s[k]) for k in data_s):
            sys.exit(f"FAILED: {piece} at t = {time}: positions or values differ from the run with all fields")
        bytes_all += os.path.getsize(os.path.join(all_dir, piece))
        bytes_selected += os.path.getsize(os.path.join(selected_dir, piece))
    print(f"  t = {time}: {len(pieces)} piece(s), arrays {sorted(expected)}")
print(f"particle .vtu files: {bytes_selected} bytes with {sorted(fields)}, {bytes_all} with all fields")
if not bytes_selected < bytes_all:
    sys.exit("FAILED: the selected fields did not make the files smaller")
print("ok")
