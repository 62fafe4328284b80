#!/usr/bin/python3
"""The method study of issue 15: scenes x methods x resolutions, each run's cost and error.

Runs dealii-mpm (the CPU backend unless --backend cuda; FP64 unless --precisions says FP32 too) on each scene at each resolution with each method, and writes
one CSV row per run: scene, method, h, points, steps, wall_s, point_updates_per_s, error, stable,
precision, backend, machine, date. Draws per scene the Pareto chart (error against wall time,
log-log, one marker per method, the front of runs no other run beats in both) and, for V1, the
convergence plot. doc/methods.md ("The study") gives the results.

  study.py --exe build/dealii-mpm --out DIR [--scenes v1,v2,v3,mms] [--methods a,b] [--reduced]
           [--csv FILE [--merge]] [--figures DIR] [--check] [--mms-exe build/tests/core/mms_study]
           [--backend cpu|cuda] [--precisions FP64,FP32]

--merge: keep the rows already in --csv except those this run measures again (same scene, method, h,
backend and precision), and draw the charts from all of them (a method added to an existing study).

--backend cuda: the runs through dealii-mpm with Backend = cuda (a build with CUDA, on a GPU machine; TPIC,
APIC and Hencky run on the CPU only and are refused there; the MMS runs in the core on the CPU whatever this says).

--precisions FP64,FP32: also the runs with the step in float: V1, V2 and V3 through dealii-mpm with
Backend/Precision = float (on the --backend given), the MMS through its core program's --precision (CPU).

--reduced: the coarse levels only (the ctest); --check: assert that every run is stable and its error
within the scene's bound (not the times), exit 1 if one is not. The bounds are what a usable method
reaches at the reduced levels: V1 2e-2 (16 and 32 cells), V2 5% (h = 0.25 m), V3 0.25 (h = 10 mm,
where the FLIP-blend methods' toes are 15-25% short), MMS 0.1 (16 and 32 cells). Linear shapes, pure FLIP and PIC are not held to
them (the stability matrix shows where the first two fail; PIC's dissipation stops the V2 beam's swing
and shortens V3's toe by 40%).

Errors:
  v1  V1 column (prm/elastic_column_2d.prm): V1's stress norm (column_error.py).
  v2  V2 cantilever (prm/cantilever_2d.prm, to 1.3 s): |first tip minimum - (-3.8248 m)| / 3.8248 m, the
      reference being our own h = 0.0625 m run with cpGIMP U (doc/methods.md).
  v3  V3 collapse (tests/prm/collapse_v3_coarse_2d.prm at h): r.m.s. of the relative errors of toe,
      top-left height and surface slope against the experiment's 0.435 m, 0.099 m and 14 deg.
  mms the manufactured solution of tests/core/manufactured_solution.h (the unit square stretched
      along its axes by +-31% over a period, kept exact by a body force), run by the core program
      mms_study (CPU backend, no deal.II): the largest over the steps of the volume-weighted L2 error
      of the positions, / the amplitude. Its wall time is the steps' alone (no set-up, no output).
"""
import argparse
import csv
import math
import os
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


def shape(name, update="none"):
    return [f"set Shape function = {name}", f"set GIMP domain update = {update}"]


# method: (label, Solver entries, other overrides)
METHODS = {
    "gimp": ("uGIMP, FLIP 0.99", shape("GIMP") + ["set FLIP fraction = 0.99"], []),
    "linear": ("linear, FLIP 0.99", shape("linear") + ["set FLIP fraction = 0.99"], []),
    "cpgimp_det_f": ("cpGIMP det F, FLIP 0.99", shape("GIMP", "det F") + ["set FLIP fraction = 0.99"], []),
    "cpgimp_f_ii": ("cpGIMP F_ii, FLIP 0.99", shape("GIMP", "F_ii") + ["set FLIP fraction = 0.99"], []),
    "cpgimp_u": ("cpGIMP U, FLIP 0.99", shape("GIMP", "U") + ["set FLIP fraction = 0.99"], []),
    "bspline2": ("B-spline 2, FLIP 0.99", shape("quadratic B-spline") + ["set FLIP fraction = 0.99"], []),
    "bspline3": ("B-spline 3, FLIP 0.99", shape("cubic B-spline") + ["set FLIP fraction = 0.99"], []),
    "gimp_pic": ("uGIMP, PIC", shape("GIMP") + ["set FLIP fraction = 0"], []),
    "gimp_flip": ("uGIMP, pure FLIP", shape("GIMP") + ["set FLIP fraction = 1"], []),
    "bspline2_pic": ("B-spline 2, PIC", shape("quadratic B-spline") + ["set FLIP fraction = 0"], []),
    "gimp_tpic": ("uGIMP, TPIC", shape("GIMP") + ["set Velocity transfer = TPIC"], []),
    "bspline2_tpic": ("B-spline 2, TPIC", shape("quadratic B-spline") + ["set Velocity transfer = TPIC"], []),
    "bspline2_apic": ("B-spline 2, APIC", shape("quadratic B-spline") + ["set Velocity transfer = APIC"], []),
    "cpgimp_u_hencky": ("cpGIMP U, FLIP 0.99, Hencky", shape("GIMP", "U") + ["set FLIP fraction = 0.99"],
                        ["@material", "  set Elastic law = Hencky", "end"]),
    "cpdi": ("CPDI, FLIP 0.99", shape("CPDI") + ["set FLIP fraction = 0.99"], []),
    "cpdi2q": ("CPDI2q, FLIP 0.99", shape("CPDI2q") + ["set FLIP fraction = 0.99"], []),
    "bspline3_gimp_f_ii": ("B-spline 3 GIMP F_ii, FLIP 0.99",
                           shape("cubic B-spline GIMP", "F_ii") + ["set FLIP fraction = 0.99"], []),
}


def v1_overrides(h):
    return ["subsection Grid", f"  set Upper corner = {h:g}, 10", f"  set Cell size = {h:g}", "end",
            "subsection Material points", "  subsection Body 1", f"    set Upper corner = {h:g}, 10", "  end", "end"]


def v1_error(out):
    return column_error.column_error(out)[0], {}


def v2_error(out, reference=-3.8248):
    """From the tip's history: its first minimum, or where it has none (PIC damps the swing away) its
    lowest deflection."""
    table = os.path.join(out, "tip.csv")
    subprocess.run([sys.executable, os.path.join(scripts, "cantilever_tip.py"), out, "--interval", "0.02", "--csv",
                    table], capture_output=True, text=True)
    if not os.path.exists(table):
        return float("nan"), {}
    d = np.loadtxt(table, delimiter=",", skiprows=1, ndmin=2)[:, 1]
    first = next((j for j in range(1, len(d) - 1) if d[j] < d[j - 1] and d[j] <= d[j + 1]), None)
    d_min = float(d[first] if first is not None else d.min())
    return abs(d_min - reference) / abs(reference), {"tip_minimum": d_min, "swings": first is not None}


def v3_error(out, toe=0.435, top=0.099, slope=14.0):
    import deposit
    r = deposit.measure(mpm_results.particles_at(out), width=0.005)
    got = (r["toe"], r["top_left_height"], r["slope"]["angle_deg"])
    rel = [(g - t) / t for g, t in zip(got, (toe, top, slope))]
    return math.sqrt(sum(e * e for e in rel) / 3), {"toe": got[0], "top_left": got[1], "slope_deg": got[2]}


# scene: (prm, material subsection name, [(h, overrides)] full, reduced levels (h), Solver entries, error, bound)
SCENES = {
    "v1": ("prm/elastic_column_2d.prm", "column",
           [(10.0 / n, v1_overrides(10.0 / n)) for n in (8, 16, 32, 64)], (10.0 / 16, 10.0 / 32), [], v1_error, 2e-2),
    "v2": ("prm/cantilever_2d.prm", "beam",
           [(h, ["subsection Grid", f"  set Cell size = {h:g}", "end"]) for h in (0.25, 0.125)], (0.25,),
           ["set End time = 1.3"], v2_error, 5e-2),
    "v3": ("tests/prm/collapse_v3_coarse_2d.prm", "aluminium bars",
           [(h, ["subsection Grid", f"  set Cell size = {h:g}", "end"]) for h in (0.01, 0.005, 0.0025)], (0.01,), [],
           v3_error, 0.25),
    # run by mms_study (run_mms), not by dealii-mpm: h = 1 / cells
    "mms": (None, None, [(1.0 / n, []) for n in (8, 16, 32, 64, 128)], (1.0 / 16, 1.0 / 32), [], None, 0.1),
}

COLUMNS = ["scene", "method", "h", "points", "steps", "wall_s", "point_updates_per_s", "error", "stable",
           "precision", "backend", "machine", "date", "details"]


def run_mms(mms_exe, method, h, precision="FP64"):
    cells = int(round(1.0 / h))
    done = subprocess.run([mms_exe, "--methods", method, "--cells", str(cells), "--precision", precision[2:]],
                          capture_output=True, text=True)
    row = {"scene": "mms", "method": method, "h": h, "precision": precision, "backend": "cpu",
           "machine": mpm_runs.machine(), "date": mpm_runs.today()}
    if done.returncode != 0:
        row.update(points="", steps="", wall_s=float("nan"), point_updates_per_s="", error="", stable="no",
                   details=done.stderr.strip()[:200])
        return row
    r = list(csv.DictReader(done.stdout.splitlines()))[0]
    row.update(points=int(r["points"]), steps=int(r["steps"]), wall_s=float(r["wall_s"]),
               point_updates_per_s=float(r["point_updates_per_s"]), error=float(r["displacement_error"]),
               stable=r["stable"], details=f"stress_error={float(r['stress_error']):.5g}")
    return row


def gpu_name():
    try:
        done = subprocess.run(["nvidia-smi", "--query-gpu=name", "--format=csv,noheader"], capture_output=True,
                              text=True)
        return done.stdout.strip().splitlines()[0]
    except (OSError, IndexError):
        return "unknown GPU"


def run_one(exe, out_root, scene, method, h, overrides, mms_exe=None, backend="cpu", precision="FP64"):
    if scene == "mms":
        return run_mms(mms_exe, method, h, precision)
    prm, material, _, _, solver, error_of, _ = SCENES[scene]
    label, method_solver, method_other = METHODS[method]
    other = [f"subsection Material {material}" if x == "@material" else x for x in method_other]
    if backend == "cuda":
        other += ["subsection Backend", "  set Backend = cuda", "end"]
    if precision == "FP32":
        other += ["subsection Backend", "  set Precision = float", "end"]
    out = os.path.join(out_root, f"{scene}-{method}-{h:g}" + ("-fp32" if precision == "FP32" else ""))
    done = mpm_runs.run(exe, prm, out, overrides + other, solver + method_solver)
    where = mpm_runs.machine() + (f", {gpu_name()}" if backend == "cuda" else "")
    row = {"scene": scene, "method": method, "h": h, "precision": precision, "backend": backend,
           "machine": where, "date": mpm_runs.today(), "wall_s": done["wall_s"],
           "steps": done.get("steps", ""), "point_updates_per_s": done.get("point_updates_per_s", "")}
    if done["status"] != "finished":
        row.update(points="", error="", stable="no", details=done["message"][:200])
        return row
    history = mpm_results.history(out)
    points = int(history["n_points"][0])
    error, details = error_of(out)
    removed = int(history["n_removed"][-1])
    details["removed"] = removed
    row.update(points=points, error=error, stable="yes" if np.isfinite(error) and removed == 0 else "no",
               details=" ".join(f"{k}={v:.5g}" if isinstance(v, float) else f"{k}={v}" for k, v in details.items()))
    return row


def pareto_front(points):
    """Indices of the (cost, error) pairs no other pair beats in both, by rising cost."""
    order = sorted(range(len(points)), key=lambda i: (points[i][0], points[i][1]))
    front, best = [], float("inf")
    for i in order:
        if points[i][1] < best:
            front.append(i)
            best = points[i][1]
    return front


def draw(rows, figures):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    markers = "osD^v<>ph*XPd"
    os.makedirs(figures, exist_ok=True)
    for scene in sorted({r["scene"] for r in rows}):
        mine = [r for r in rows if r["scene"] == scene and r["stable"] == "yes" and float(r["error"]) > 0]
        if not mine:
            continue
        fig, ax = plt.subplots(figsize=(10, 5.5))
        backends = sorted({r.get("backend", "cpu") for r in mine})
        precisions = sorted({r.get("precision", "FP64") for r in mine}, reverse=True)
        for k, method in enumerate(METHODS):
            for backend in backends:
                for precision in precisions:
                    pts = [(float(r["wall_s"]), float(r["error"])) for r in mine
                           if r["method"] == method and r.get("backend", "cpu") == backend
                           and r.get("precision", "FP64") == precision]
                    if pts:
                        style = {"mfc": "none"} if backend == "cuda" else {}
                        if precision == "FP32":  # a smaller marker edged in black
                            style.update(ms=4, mec="k")
                        label = (METHODS[method][0] + (" (cuda)" if backend == "cuda" else "")
                                 + (" FP32" if precision == "FP32" else ""))
                        ax.loglog(*zip(*pts), markers[k % len(markers)], label=label, alpha=0.8,
                                  color=plt.cm.tab20(k % 20), **style)
        pts = [(float(r["wall_s"]), float(r["error"])) for r in mine]
        front = [pts[i] for i in pareto_front(pts)]
        ax.step(*zip(*front), where="post", color="k", lw=1, label="Pareto front")
        ax.set_xlabel("wall time (s), " + ("FP64 and FP32 (small, black edge)" if "FP32" in precisions else "FP64")
                      + ("; filled: CPU backend, hollow: CUDA" if "cuda" in backends else ", CPU backend"))
        ax.set_ylabel("error")
        where = sorted({r["machine"] for r in mine})
        ax.set_title(f"{scene.upper()}: error against cost ({'; '.join(where)})", fontsize=7)
        ax.legend(fontsize=6, loc="center left", bbox_to_anchor=(1.01, 0.5))
        fig.tight_layout()
        fig.savefig(os.path.join(figures, f"study_{scene}_pareto.png"), dpi=110)
        plt.close(fig)
    for scene, what, title in (("v1", "V1 error norm", "V1 column"),
                               ("mms", "MMS position error / amplitude", "Manufactured solution")):
        mine = [r for r in rows if r["scene"] == scene and r["stable"] == "yes" and r.get("backend", "cpu") == "cpu"
                and r.get("precision", "FP64") == "FP64"]
        if not mine:
            continue
        fig, ax = plt.subplots(figsize=(9, 5))
        for k, method in enumerate(METHODS):
            pts = sorted((float(r["h"]), float(r["error"])) for r in mine if r["method"] == method)
            if pts:
                ax.loglog(*zip(*pts), "-" + markers[k % len(markers)], label=METHODS[method][0],
                          color=plt.cm.tab20(k % 20))
        h = np.array(sorted({float(r["h"]) for r in mine}))
        middle = [float(r["error"]) for r in mine if float(r["h"]) == h[len(h) // 2]]
        ax.loglog(h, min(middle) * (h / h[len(h) // 2]) ** 2, "k:", label="order 2")
        ax.set_xlabel("cell size h (m)")
        ax.set_ylabel(what)
        ax.set_title(f"{title}: convergence (CPU backend, FP64)", fontsize=9)
        ax.legend(fontsize=7, loc="center left", bbox_to_anchor=(1.01, 0.5))
        fig.tight_layout()
        fig.savefig(os.path.join(figures, f"study_{scene}_convergence.png"), dpi=110)
        plt.close(fig)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--exe", required=True)
    ap.add_argument("--out", required=True, help="folder for the runs")
    ap.add_argument("--scenes", default=",".join(SCENES))
    ap.add_argument("--methods", default=",".join(METHODS))
    ap.add_argument("--reduced", action="store_true")
    ap.add_argument("--csv")
    ap.add_argument("--merge", action="store_true", help="keep --csv's other rows (see above)")
    ap.add_argument("--figures")
    ap.add_argument("--check", action="store_true")
    ap.add_argument("--backend", choices=["cpu", "cuda"], default="cpu")
    ap.add_argument("--precisions", default="FP64", help="FP64, FP32 or both")
    ap.add_argument("--mms-exe", help="the core program mms_study (default: tests/core/mms_study beside --exe)")
    args = ap.parse_args()
    mms_exe = args.mms_exe or os.path.join(os.path.dirname(os.path.abspath(args.exe)), "tests", "core", "mms_study")
    precisions = args.precisions.split(",")
    for p in precisions:
        if p not in ("FP64", "FP32"):
            sys.exit(f"study.py: --precisions: '{p}' is not one of FP64, FP32")
    rows = []
    for scene in args.scenes.split(","):
        levels, reduced = SCENES[scene][2], SCENES[scene][3]
        for method in args.methods.split(","):
            for h, overrides in levels:
                if args.reduced and not any(abs(h - r) < 1e-12 for r in reduced):
                    continue
                for precision in precisions:
                    row = run_one(args.exe, os.path.abspath(args.out), scene, method, h, overrides, mms_exe,
                                  args.backend, precision)
                    rows.append(row)
                    print(f"{scene} {METHODS[method][0]:32s} {precision} h={h:<8.4g} "
                          f"error={row['error']!s:22.22s} wall={row['wall_s']:.2f}s stable={row['stable']} "
                          f"{row['details']}", flush=True)
    all_rows = rows
    if args.merge and args.csv and os.path.exists(args.csv):
        def key(r):
            return (r["scene"], r["method"], float(r["h"]), r.get("backend", "cpu"), r.get("precision", "FP64"))
        measured = {key(r) for r in rows}
        kept = [r for r in csv.DictReader(open(args.csv)) if key(r) not in measured]
        all_rows = kept + rows
    if args.csv:
        with open(args.csv, "w", newline="") as f:
            w = csv.DictWriter(f, fieldnames=COLUMNS)
            w.writeheader()
            w.writerows(all_rows)
    if args.figures:
        draw(all_rows, args.figures)
    if args.check:
        failed = [r for r in rows if r["stable"] != "yes" or not float(r["error"]) <= SCENES[r["scene"]][6]]
        for r in failed:
            print(f"FAILED: {r['scene']} {r['method']} h={r['h']:g}: error {r['error']} "
                  f"(bound {SCENES[r['scene']][6]:g}), stable {r['stable']} {r['details']}")
        sys.exit(1 if failed else 0)


if __name__ == "__main__":
    main()
