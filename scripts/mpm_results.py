"""Read dealii-mpm output: the time series of particles (.pvd -> .pvtu -> .vtu pieces)
and the time history (history.csv). Needs Debian's python3-numpy and python3-meshio."""
import csv
import math
import os
import xml.etree.ElementTree as ET

import numpy as np


def pvd_records(output_dir, name="particles"):
    """[(time, pvtu file name)] in the order written."""
    root = ET.parse(os.path.join(output_dir, name + ".pvd")).getroot()
    return [(float(d.get("timestep")), d.get("file")) for d in root.iter("DataSet")]


def read_pvtu(output_dir, pvtu):
    """Points and point data of all pieces of one .pvtu file, merged."""
    import meshio  # only here: the particle tables and histories need numpy alone
    root = ET.parse(os.path.join(output_dir, pvtu)).getroot()
    pieces = [p.get("Source") for p in root.iter("Piece")]
    points, data = [], {}
    for piece in pieces:
        m = meshio.read(os.path.join(output_dir, piece))
        points.append(m.points)
        for key, value in m.point_data.items():
            data.setdefault(key, []).append(np.asarray(value, dtype=float))
    result = {key: np.concatenate(v) for key, v in data.items()}
    result["position"] = np.concatenate(points).astype(float)
    return result


def particles_at(output_dir, index=-1):
    """Particle data of output number `index` (default: the last); also its time."""
    time, pvtu = pvd_records(output_dir)[index]
    data = read_pvtu(output_dir, pvtu)
    data["time"] = time
    return data


def history(output_dir):
    """The time history as a dict of numpy arrays, one per column."""
    with open(os.path.join(output_dir, "history.csv")) as f:
        rows = list(csv.DictReader(f))
    return {key: np.array([float(r[key]) for r in rows]) for key in rows[0]}


def check_limits(checks, digits=4):
    """Prints one line per (name, value, (low, high) or None) and returns True if a value is outside its
    limits or not finite; checks without limits are skipped. For the scripts' --option LO,HI checks."""
    failed = False
    for name, value, lim in checks:
        if lim is None:
            continue
        ok = math.isfinite(value) and lim[0] <= value <= lim[1]
        print(f"  check {name}: {value:.{digits}g} in [{lim[0]:g}, {lim[1]:g}]: {'ok' if ok else 'FAILED'}")
        failed |= not ok
    return failed


def bounds(text):
    """argparse type of the scripts' --option LO,HI checks."""
    lo, hi = (float(v) for v in text.split(","))
    return lo, hi
