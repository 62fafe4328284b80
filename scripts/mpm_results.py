"""Read dealii-mpm output: the time series of particles (.pvd -> .pvtu -> .vtu pieces)
and the time history (history.csv). Needs numpy; uses meshio where installed, else reads deal.II's
.vtu pieces with numpy alone (the GPU hosts have no meshio)."""
import csv
import math
import os
import xml.etree.ElementTree as ET

import numpy as np


def pvd_records(output_dir, name="particles"):
    """[(time, pvtu file name)] in the order written."""
    root = ET.parse(os.path.join(output_dir, name + ".pvd")).getroot()
    return [(float(d.get("timestep")), d.get("file")) for d in root.iter("DataSet")]


VTK_TYPES = {"Float32": np.float32, "Float64": np.float64, "Int32": np.int32, "Int64": np.int64,
             "UInt32": np.uint32, "UInt64": np.uint64, "UInt8": np.uint8, "Int8": np.int8}


def _binary_array(element, compressed):
    """The values of a DataArray in VTK's base64 "binary" format (deal.II's: UInt32 headers;
    header and data encoded separately; zlib blocks where the file names vtkZLibDataCompressor)."""
    import base64
    import zlib
    text = "".join(element.text.split())
    dtype = VTK_TYPES[element.get("type")]
    if not compressed:
        size = np.frombuffer(base64.b64decode(text[:8]), np.uint32)[0]
        raw = base64.b64decode(text[8:])[:size]
    else:
        n_blocks = int(np.frombuffer(base64.b64decode(text[:16]), np.uint32)[0])
        header_chars = 4 * math.ceil(4 * (3 + n_blocks) / 3)
        sizes = np.frombuffer(base64.b64decode(text[:header_chars]), np.uint32)[3:3 + n_blocks]
        blob = base64.b64decode(text[header_chars:])
        offsets = [0] + [int(s) for s in np.cumsum(sizes)]
        raw = b"".join(zlib.decompress(blob[offsets[k]:offsets[k + 1]]) for k in range(n_blocks))
    values = np.frombuffer(raw, dtype)
    components = int(element.get("NumberOfComponents", "1"))
    return values.reshape(-1, components) if components > 1 else values


def read_vtu(path):
    """(points, {name: point data}) of one .vtu piece as deal.II writes it, with numpy alone: the
    fallback where meshio is not installed (the GPU hosts)."""
    root = ET.parse(path).getroot()
    compressed = root.get("compressor") is not None
    points = _binary_array(root.find(".//Points/DataArray"), compressed)
    data = {a.get("Name"): _binary_array(a, compressed) for a in root.findall(".//PointData/DataArray")}
    return points, data


def read_pvtu(output_dir, pvtu):
    """Points and point data of all pieces of one .pvtu file, merged."""
    try:
        import meshio  # only here: the particle tables and histories need numpy alone

        def read(path):
            m = meshio.read(path)
            return m.points, m.point_data
    except ImportError:
        read = read_vtu
    root = ET.parse(os.path.join(output_dir, pvtu)).getroot()
    pieces = [p.get("Source") for p in root.iter("Piece")]
    points, data = [], {}
    for piece in pieces:
        piece_points, piece_data = read(os.path.join(output_dir, piece))
        points.append(piece_points)
        for key, value in piece_data.items():
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
