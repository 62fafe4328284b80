#!/usr/bin/python3
"""Write the V6 column-collapse scene (prm/column_aspect_ratio_3d.prm) for one aspect ratio.

Usage: column_aspect_ratio.py --lambda L [--cells-per-radius N] [--base friction|no-slip]
                              [--friction-coefficient MU] [--damping D] [--backend cpu|cuda]
                              [--shape-function GIMP|linear] [--flip-fraction ALPHA]
                              [--end-time T] [--output DIR] [--table-only] [--template PRM] > scene.prm

lambda0 = h0 / r0 is the one parameter of the scene: it sets the column height, the grid that
encloses the deposit and the end time (the relations are in the template's header). The other
options change the base (rough with Coulomb friction, or no-slip), the local damping, the
resolution (cells across r0 = 1 m) and the backend. Needs only the standard library (runs on
the GPU hosts too).
"""
import argparse
import math
import os
import sys

R0 = 1.0   # column radius (m)
G = 9.81   # gravity (m/s^2)


def fit(aspect_ratio):
    """The experiments' fit of the normalised run-out (r_inf - r0) / r0 (Wyser 2022, ch. 7)."""
    return 0.63 * aspect_ratio ** 1.30


def scene_geometry(aspect_ratio, cell):
    """Column height, horizontal and vertical grid extents (whole cells) and end time."""
    height = aspect_ratio * R0
    side = R0 * (1 + 1.6 * fit(aspect_ratio)) + 4 * cell
    side = math.ceil(side / cell - 1e-9) * cell
    top = math.ceil((height + 2 * cell) / cell - 1e-9) * cell
    end_time = 5 * math.sqrt(height / G) + 0.5
    return height, side, top, end_time


def set_entries(lines, changes):
    """Rewrite 'set KEY = VALUE' lines; changes maps (subsection path, key) -> value. Every
    change must find its line (a template that lost an entry is an error, not a silent scene)."""
    path, out, done = [], [], set()
    for line in lines:
        words = line.strip()
        if words.startswith("subsection "):
            path.append(words[len("subsection "):].strip())
        elif words == "end":
            path.pop()
        elif words.startswith("set ") and "=" in words:
            key = words[4:words.index("=")].strip()
            where = (tuple(path), key)
            if where in changes:
                line = f"{line[:line.index('=')]}= {changes[where]}\n"
                done.add(where)
        out.append(line)
    missing = set(changes) - done
    if missing:
        sys.exit(f"column_aspect_ratio.py: the template has no entry {sorted(missing)}")
    return out


def main():
    here = os.path.dirname(os.path.abspath(__file__))
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--lambda", dest="aspect_ratio", type=float, required=True, help="h0 / r0, > 0")
    parser.add_argument("--cells-per-radius", type=int, default=20)
    parser.add_argument("--base", choices=["friction", "no-slip"], default="friction")
    parser.add_argument("--friction-coefficient", type=float, default=math.tan(math.radians(37.55)))
    parser.add_argument("--damping", type=float, default=0.0)
    parser.add_argument("--backend", choices=["cpu", "cuda"], default="cpu")
    parser.add_argument("--shape-function", choices=["GIMP", "linear"], default="GIMP")
    parser.add_argument("--flip-fraction", type=float, default=0.99)
    parser.add_argument("--end-time", type=float, default=None, help="default: 5 sqrt(h0 / g) + 0.5 s")
    parser.add_argument("--output", default=None, help="the run's output directory")
    parser.add_argument("--table-only", action="store_true",
                        help="write the particle table (CSV, for column_runout.py) and no .vtu files")
    parser.add_argument("--template", default=os.path.join(here, "..", "prm", "column_aspect_ratio_3d.prm"))
    args = parser.parse_args()
    if not args.aspect_ratio > 0:
        sys.exit("column_aspect_ratio.py: --lambda must be > 0")
    if args.cells_per_radius < 1:
        sys.exit("column_aspect_ratio.py: --cells-per-radius must be >= 1")

    cell = R0 / args.cells_per_radius
    height, side, top, end_time = scene_geometry(args.aspect_ratio, cell)
    if args.end_time is not None:
        end_time = args.end_time
    number = lambda x: f"{x:.10g}"
    changes = {
        (("Grid",), "Upper corner"): f"{number(side)}, {number(side)}, {number(top)}",
        (("Grid",), "Cell size"): number(cell),
        (("Boundary conditions",), "z min"): args.base,
        (("Boundary conditions",), "Friction coefficient"): number(args.friction_coefficient),
        (("Solver",), "End time"): number(end_time),
        (("Solver",), "Local damping"): number(args.damping),
        (("Solver",), "Shape function"): args.shape_function,
        (("Solver",), "GIMP domain update"): "det F" if args.shape_function == "GIMP" else "none",
        (("Solver",), "FLIP fraction"): number(args.flip_fraction),
        (("Material points", "Body 1"), "Upper corner"): f"{number(R0)}, {number(R0)}, {number(height)}",
    }
    if args.table_only:
        changes[(("Output",), "Write particles")] = "false"
        changes[(("Output",), "Write particle table")] = "true"
    if args.output:
        changes[(("Output",), "Directory")] = args.output
    with open(args.template) as f:
        lines = set_entries(f.readlines(), changes)
    sys.stdout.write(f"# Written by scripts/column_aspect_ratio.py: lambda0 = {number(args.aspect_ratio)}, "
                     f"{args.cells_per_radius} cells per r0, base {args.base}, D = {number(args.damping)}, "
                     f"{args.shape_function}, FLIP {number(args.flip_fraction)}, backend {args.backend}\n")
    sys.stdout.writelines(lines)
    if args.backend == "cuda":
        sys.stdout.write("\nsubsection Backend\n  set Backend = cuda\nend\n")


if __name__ == "__main__":
    main()
