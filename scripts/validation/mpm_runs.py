"""Running dealii-mpm on a scene with overrides, for the scripts that sweep methods (stability.py,
study.py): a copy of the prm file with entries appended (later entries win), the run, its outcome
(finished, stopped by the instability check with its message, or crashed) and its cost as the
program reports it."""
import os
import platform
import re
import shutil
import subprocess
import time

root = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))  # scripts/validation/ -> repo


def machine():
    """Host name, CPU model and core count, for the records of where a run was measured."""
    model = platform.processor() or "unknown CPU"
    try:
        with open("/proc/cpuinfo") as f:
            model = next(line.split(":", 1)[1].strip() for line in f if line.startswith("model name"))
    except (OSError, StopIteration):
        pass
    return f"{platform.node()}, {model}, {os.cpu_count()} cores"


def today():
    return time.strftime("%Y-%m-%d")


def write_scene(prm, out, overrides=(), solver=()):
    """out/scene.prm: prm (relative to the repository) with the output folder, `overrides` (lines
    outside Solver) and `solver` (entries of subsection Solver) appended."""
    shutil.rmtree(out, ignore_errors=True)
    os.makedirs(out)
    copy = os.path.join(out, "scene.prm")
    with open(os.path.join(root, prm)) as f:
        text = f.read()
    lines = ["", "subsection Output", f"  set Directory = {out}", "  set Progress interval = 0", "end"]
    lines += list(overrides) + ["subsection Solver"] + ["  " + s for s in solver] + ["end"]
    with open(copy, "w") as f:
        f.write(text + "\n".join(lines) + "\n")
    return copy


def run(exe, prm, out, overrides=(), solver=()):
    """Runs the scene; returns {"status": finished|unstable|crash, "message", "steps", "wall_s",
    "point_updates_per_s"} (cost from the program's closing line, where it finished)."""
    copy = write_scene(prm, out, overrides, solver)
    started = time.monotonic()
    done = subprocess.run([exe, copy], capture_output=True, text=True)
    result = {"status": "finished", "message": "", "wall_s": time.monotonic() - started}
    if done.returncode != 0:
        lines = [line for line in done.stderr.splitlines() + done.stdout.splitlines() if line.strip()]
        unstable = next((line.strip() for line in lines if "became unstable" in line), None)
        if unstable is not None and 0 < done.returncode < 128:
            result.update(status="unstable", message=unstable.split(" To stabilise")[0])
        else:
            result.update(status="crash", message=f"exit {done.returncode}: " + " | ".join(lines[-3:]))
        return result
    m = re.search(r"after (\d+) steps in ([0-9.eE+-]+) s wall \(([0-9.eE+-]+) point-updates/s\)", done.stdout)
    if m:
        result.update(steps=int(m.group(1)), wall_s=float(m.group(2)), point_updates_per_s=float(m.group(3)))
    return result
