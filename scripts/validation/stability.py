#!/usr/bin/python3
"""The stability matrix of issue 15: failure scenes x methods (doc/methods.md, "Stability matrix").

Every cell is one run of dealii-mpm: a scene, where some method is known to fail, run with one method.
The cell is "stable" when the run ends and the scene's measure is within its bound, "fails" when the
program stops it with its message (a blow-up found by the instability check) or the measure is beyond
the bound. A crash (a signal, or no message) is neither: it fails every test.

  stability.py run SCENE METHOD --exe EXE --out DIR [--expect stable|fails] [--record DIR]
      runs one cell, prints the measure and the outcome, writes DIR/SCENE.METHOD.json; with --expect
      exits 1 unless the outcome is the expected one (the ctest of the cell, label "stability").
  stability.py matrix RECORDS_DIR [--doc doc/methods.md]
      the table of the recorded cells (markdown), written between the markers of the doc page.
  stability.py list
      the scenes and methods.
"""
import argparse
import glob
import json
import os
import shutil
import subprocess
import sys

import numpy as np

here = os.path.dirname(os.path.abspath(__file__))
scripts = os.path.dirname(here)  # scripts/: mpm_results, deposit, cantilever_tip.py
sys.path.insert(0, scripts)
sys.path.insert(0, here)
import column_error  # noqa: E402
import mpm_results  # noqa: E402
import mpm_runs  # noqa: E402

# The methods: Solver entries set on top of the scene's own (its transfer, scheme and damping stay).
METHODS = {
    "linear": ("linear", ["set Shape function = linear", "set GIMP domain update = none"]),
    "ugimp": ("uGIMP", ["set Shape function = GIMP", "set GIMP domain update = none"]),
    "cpgimp_det_f": ("cpGIMP det F", ["set Shape function = GIMP", "set GIMP domain update = det F"]),
    "cpgimp_f_ii": ("cpGIMP F_ii", ["set Shape function = GIMP", "set GIMP domain update = F_ii"]),
    "cpgimp_u": ("cpGIMP U", ["set Shape function = GIMP", "set GIMP domain update = U"]),
    "bspline2": ("quadratic B-spline", ["set Shape function = quadratic B-spline",
                                        "set GIMP domain update = none"]),
    "bspline3": ("cubic B-spline", ["set Shape function = cubic B-spline", "set GIMP domain update = none"]),
    "ugimp_tpic": ("uGIMP, TPIC", ["set Shape function = GIMP", "set GIMP domain update = none",
                                   "set Velocity transfer = TPIC"]),
    "bspline2_apic": ("quadratic B-spline, APIC", ["set Shape function = quadratic B-spline",
                                                   "set GIMP domain update = none", "set Velocity transfer = APIC"]),
    # Material entries: "@material" stands for each material of the scene's prm.
    "cpgimp_u_hencky": ("cpGIMP U, Hencky", ["set Shape function = GIMP", "set GIMP domain update = U"],
                        ["@material", "  set Elastic law = Hencky", "end"]),
    "cpdi": ("CPDI", ["set Shape function = CPDI", "set GIMP domain update = none"]),
    "cpdi2q": ("CPDI2q", ["set Shape function = CPDI2q", "set GIMP domain update = none"]),
    "bspline3_gimp_f_ii": ("cubic B-spline GIMP F_ii", ["set Shape function = cubic B-spline GIMP",
                                                        "set GIMP domain update = F_ii"]),
}


def material_lines(prm, method):
    """The method's material entries, once for every material the prm names."""
    lines = METHODS[method][2] if len(METHODS[method]) > 2 else []
    if not lines:
        return []
    with open(os.path.join(here, "..", "..", prm)) as f:
        names = next(line.split("=", 1)[1] for line in f if line.strip().startswith("set Names"))
    result = []
    for name in (n.strip() for n in names.split(",") if n.strip()):
        result += [f"subsection Material {name}" if x == "@material" else x for x in lines]
    return result


def column(cells, extra_solver=(), extra=()):
    """V1 (prm/elastic_column_2d.prm) at `cells` cells over its 10 m, one cell wide."""
    h = 10.0 / cells
    return (["subsection Grid", f"  set Upper corner = {h:g}, 10", f"  set Cell size = {h:g}", "end",
             "subsection Material points", "  subsection Body 1", f"    set Upper corner = {h:g}, 10", "  end",
             "end"] + list(extra), list(extra_solver))


def measure_column(outs, g=9.81, bound=1e-2):
    error, p = column_error.column_error(outs["run"], g=g)
    error = abs(error)  # g < 0 (gravity up) flips the sign of the norm's scale
    return {"error": error, "points": len(p["mass"])}, error <= bound, f"V1 norm {error:.3g} (bound {bound:g})"


def measure_refinement(outs, bound=5e-2):
    """Cell crossing: refinement must lower the error (16 -> 32 cells), and it must stay below bound."""
    coarse, fine = (column_error.column_error(outs[k])[0] for k in ("16 cells", "32 cells"))
    ok = fine < coarse and fine <= bound
    return ({"error_16": coarse, "error_32": fine}, ok,
            f"V1 norm {coarse:.3g} at 16 cells, {fine:.3g} at 32 ({'falls' if fine < coarse else 'does not fall'}"
            f" under refinement; bound {bound:g})")


def measure_time_step(outs, tolerance=0.25):
    """The step at the elastic limit must give the error of CFL 0.5 within the tolerance (relative)."""
    usual, limit = (column_error.column_error(outs[k])[0] for k in ("CFL 0.5", "h / c_el"))
    ok = abs(limit - usual) <= tolerance * usual
    return ({"error_cfl_0.5": usual, "error_limit": limit}, ok,
            f"V1 norm {limit:.3g} at the limit against {usual:.3g} at CFL 0.5 (within {tolerance:.0%}: "
            f"{'yes' if ok else 'no'})")


def measure_removed(out):
    h = mpm_results.history(out)
    return int(h["n_removed"][-1])


def measure_stretch(outs):
    values, ok, text = measure_column(outs, g=-9.81)
    values["removed"] = measure_removed(outs["run"])
    if values["removed"]:
        return values, False, f"{values['removed']} points torn off and out of the grid; " + text
    return values, ok, text


def measure_block(outs, rho=2000.0, g=9.81, height=1.0, width=1.0, h=0.0625, factor=4.0):
    """Locking: the pressure checkerboard, the r.m.s. deviation of a point's in-plane pressure
    -(s_xx + s_yy) / 2 from the mean of the points of its cell, over rho g H, for the points more
    than 2 h from the free faces. At rest the exact pressure rho g (H - y) / 2 varies within a cell
    by +-rho g h / 8 at the points (r.m.s. h / (8 H)); the bound is `factor` times that."""
    p = mpm_results.particles_at(outs["run"])
    x0, y0 = p["initial_position"][:, 0], p["initial_position"][:, 1]
    inner = (x0 < width - 2 * h) & (y0 > 2 * h) & (y0 < height - 2 * h)
    pressure = -(p["stress_xx"] + p["stress_yy"]) / 2
    cell = np.floor(p["position"][:, 0] / h).astype(int) + 100000 * np.floor(p["position"][:, 1] / h).astype(int)
    deviation = []
    for c in np.unique(cell[inner]):
        mine = (cell == c) & inner
        if mine.sum() > 1:
            deviation.extend(pressure[mine] - pressure[mine].mean())
    checkerboard = float(np.sqrt(np.mean(np.square(deviation))) / (rho * g * height))
    bound = factor * h / (8 * height)
    v0 = p["initial_volume"][inner]
    e_yy = float(np.sum(np.abs(p["stress_yy"] + rho * g * (height - y0))[inner] * v0) / (rho * g * height * v0.sum()))
    return ({"checkerboard": checkerboard, "error_yy_inner": e_yy}, checkerboard <= bound,
            f"pressure checkerboard {checkerboard:.3g} rho g H (bound {bound:.3g}: {factor:g} x the exact "
            f"field's own within a cell); inner sigma_yy error {e_yy:.3g}")


def measure_cantilever(outs, reference=-3.8248, tolerance=0.02, least_scale=0.3):
    run = subprocess.run([sys.executable, os.path.join(scripts, "cantilever_tip.py"), outs["run"], "--interval", "0.02"],
                         capture_output=True, text=True)
    line = run.stdout.strip().splitlines()[-1] if run.stdout.strip() else run.stderr.strip()
    if run.returncode != 0 or "first deflection minimum" not in line:
        return {}, False, "no deflection minimum: " + line
    words = line.split()
    d_min = float(words[words.index("minimum") + 1])
    scale = float(words[-1])
    ok_tip = abs(d_min - reference) <= tolerance * abs(reference)
    ok_scale = scale >= least_scale
    text = (f"tip minimum {d_min:.4f} m (reference {reference} m, within {tolerance:.0%}: "
            f"{'yes' if ok_tip else 'no'}), smallest domain scale {scale:.3f} (least {least_scale})")
    return {"tip_minimum": d_min, "domain_scale": scale}, ok_tip and ok_scale, text


def measure_deposit(outs):
    import deposit
    out = outs["run"]
    data = mpm_results.particles_at(out)
    r = deposit.measure(data, width=0.005)
    h = mpm_results.history(out)
    checks = {"toe": (r.get("toe", float("nan")), (0.39, 0.48)),
              "top_left": (r.get("top_left_height", float("nan")), (0.090, 0.1005)),
              "slope": (r["slope"]["angle_deg"], (9.0, 18.0))}
    values = {k: float(v) for k, (v, _) in checks.items()}
    values["removed"] = int(h["n_removed"][-1])
    values["rest"] = float(h["kinetic_energy"][-1] / h["work_of_gravity"][-1])  # as check_history --at-rest
    ok = values["removed"] == 0 and values["rest"] <= 0.03
    ok = ok and all(np.isfinite(v) and lo <= v <= hi for v, (lo, hi) in checks.values())
    text = ", ".join(f"{k} {v:.4g} in [{lo:g}, {hi:g}]" for k, (v, (lo, hi)) in checks.items())
    return values, ok, text + (f", {values['removed']} points left the grid, final kinetic energy "
                               f"{values['rest']:.2g} of the work of gravity (at rest: <= 0.03)")


def measure_energy(outs, bound=1.05):
    """A free elastic block, stress-free at the start: its kinetic energy can never exceed the initial one."""
    h = mpm_results.history(outs["run"])
    gain = float(np.max(h["kinetic_energy"]) / h["kinetic_energy"][0])
    return ({"kinetic_energy_gain": gain}, gain <= bound,
            f"largest kinetic energy {gain:.3f} of the initial (bound {bound:g})")


def one_run(overrides=(), solver=()):
    return {"run": (list(overrides), list(solver))}


# scene: (title, what fails where, prm, {run label: (overrides outside Solver, Solver overrides)}, measure)
SCENES = {
    "cell_crossing": (
        "Cell crossing (V1 column, 78% compression, 16 and 32 cells)",
        "points cross cell faces as the column compresses; linear shapes' gradients jump",
        "prm/elastic_column_2d.prm", {"16 cells": column(16), "32 cells": column(32)}, measure_refinement),
    "rotation": (
        "Rotation (V2 cantilever, h = 0.25 m)",
        "F_ii domains vanish where the beam turns",
        "prm/cantilever_2d.prm", one_run(solver=["set End time = 1.3"]), measure_cantilever),
    "locking": (
        "Volumetric locking (block at rest, nu = 0.49, no remedy)",
        "nearly incompressible: the points' pressures lock into a checkerboard",
        "tests/stability/incompressible_block_2d.prm", one_run(), measure_block),
    "stretch": (
        "Stretch (V1 column hanging, gravity up, E = 20 kPa)",
        "points drift more than a stencil apart: numerical fracture",
        "prm/elastic_column_2d.prm",
        {"run": column(16, ["set Gravity = 0, 9.81"],
                       ["subsection Material column", "  subsection linear elastic",
                        "    set Young's modulus = 2e4", "  end", "end",
                        "subsection Grid", "  set Upper corner = 0.625, 40", "end"])},
        measure_stretch),
    "flip_noise": (
        "Pure FLIP (V3 collapse, h = 5 mm, no damping)",
        "FLIP keeps velocities the grid does not see: noise, points thrown out",
        "tests/prm/collapse_v3_coarse_2d.prm",
        one_run(solver=["set FLIP fraction = 1"]), measure_deposit),
    "time_step_limit": (
        "Time step at the elastic limit h / c_el (V1 column, 16 cells)",
        "a fixed step at the limit the program allows (beyond it the run is refused)",
        "prm/elastic_column_2d.prm",
        {"CFL 0.5": column(16), "h / c_el": column(16, ["set Time step = fixed", "set Fixed time step = 0.0559"])},
        measure_time_step),
    "usl_light_nodes": (
        "USL with light nodes (free block, fixed step at 0.73 of h / c_el)",
        "a point alone on a node's edge gives it a tiny mass and a huge velocity",
        "tests/prm/unstable_usl_2d.prm", one_run(), measure_energy),
}


def run_cell(scene, method, exe, out):
    _, _, prm, runs, measure = SCENES[scene]
    shutil.rmtree(out, ignore_errors=True)
    record = {"scene": scene, "method": method, "date": mpm_runs.today(), "machine": mpm_runs.machine()}
    outs = {}
    for k, (label, (overrides, solver)) in enumerate(runs.items()):
        outs[label] = os.path.join(out, str(k)) if len(runs) > 1 else out
        done = mpm_runs.run(exe, prm, outs[label], overrides + material_lines(prm, method),
                            solver + METHODS[method][1])
        where = f" ({label})" if len(runs) > 1 else ""
        if done["status"] == "unstable":
            record.update(outcome="fails", reason=f"stopped{where}: " + done["message"])
            return record
        if done["status"] == "crash":
            record.update(outcome="crash", reason=f"{done['message']}{where}")
            return record
    values, ok, text = measure(outs)
    record.update(values=values, outcome="stable" if ok else "fails", reason=text)
    return record


def matrix(records_dir):
    cells = {}
    for path in glob.glob(os.path.join(records_dir, "*.json")):
        with open(path) as f:
            r = json.load(f)
        cells[(r["scene"], r["method"])] = r
    methods = [m for m in METHODS if any(m == k[1] for k in cells)]
    where = sorted({(r.get("date", "?"), r.get("machine", "?")) for r in cells.values()})
    lines = ["Recorded " + "; ".join(f"{d} on {m}" for d, m in where) + ".", "","| scene | " + " | ".join(METHODS[m][0] for m in methods) + " |",
             "|---|" + "---|" * len(methods)]
    for scene, (title, *_rest) in SCENES.items():
        row = []
        for m in methods:
            r = cells.get((scene, m))
            row.append("-" if r is None else ("**fails**" if r["outcome"] == "fails" else r["outcome"]))
        lines.append(f"| {title} | " + " | ".join(row) + " |")
    lines.append("")
    lines.append("What each cell measured:")
    lines.append("")
    for scene in SCENES:
        for m in methods:
            r = cells.get((scene, m))
            if r is not None:
                lines.append(f"- {scene} / {METHODS[m][0]}: {r['outcome']}; {r['reason']}")
    return "\n".join(lines) + "\n"


def write_into_doc(doc, table):
    begin, end = "<!-- stability matrix: begin (scripts/validation/stability.py matrix) -->", "<!-- stability matrix: end -->"
    with open(doc) as f:
        text = f.read()
    if begin not in text or end not in text:
        sys.exit(f"stability.py: {doc} lacks the markers {begin} ... {end}")
    head, rest = text.split(begin, 1)
    _, tail = rest.split(end, 1)
    with open(doc, "w") as f:
        f.write(head + begin + "\n" + table + end + tail)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = ap.add_subparsers(dest="command", required=True)
    r = sub.add_parser("run")
    r.add_argument("scene", choices=SCENES)
    r.add_argument("method", choices=METHODS)
    r.add_argument("--exe", required=True)
    r.add_argument("--out", required=True)
    r.add_argument("--expect", choices=["stable", "fails"])
    r.add_argument("--record")
    m = sub.add_parser("matrix")
    m.add_argument("records")
    m.add_argument("--doc")
    sub.add_parser("list")
    args = ap.parse_args()
    if args.command == "list":
        for s, v in SCENES.items():
            print(f"scene {s}: {v[0]}; {v[1]}")
        for k, v in METHODS.items():
            print(f"method {k}: {v[0]}")
        return
    if args.command == "matrix":
        table = matrix(args.records)
        if args.doc:
            write_into_doc(args.doc, table)
        print(table)
        return
    record = run_cell(args.scene, args.method, args.exe, os.path.abspath(args.out))
    print(f"{args.scene} / {METHODS[args.method][0]}: {record['outcome']}; {record['reason']}")
    if args.record:
        os.makedirs(args.record, exist_ok=True)
        with open(os.path.join(args.record, f"{args.scene}.{args.method}.json"), "w") as f:
            json.dump(record, f, indent=1)
    if record["outcome"] == "crash" or (args.expect and record["outcome"] != args.expect):
        print(f"FAILED: expected {args.expect}, got {record['outcome']}")
        sys.exit(1)


if __name__ == "__main__":
    main()
