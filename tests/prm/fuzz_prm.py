#!/usr/bin/python3
"""Mutation test of the parameter-file input (doc/guards.md, "Sanitizers and the mutation test").

Takes the shipped scenes (prm/*.prm, tests/prm/*.prm; a few slow ones skipped, see SKIPPED),
applies seeded mutations to them (delete, duplicate or swap lines, a number replaced by 0, -1,
1e308, nan, a huge integer, a word or nothing, a file cut short, an 'end' cut or added, garbage
characters, a broken include, another or a wrong selection value, an extreme value for any
entry the program knows), makes each scene short by appending overrides (3 steps, output into
a folder of its own), and runs dealii-mpm on it with a hard time limit. Every run must end
either with exit status 0 or with a clean error: a status from 1 to 127 and the program's
'dealii-mpm: error' message on stderr. A signal (a crash, an abort, 'terminate called'), a
status of 128 or more, or a run that outlasts the limit (a hang) fails the test; each failure
is printed with the seed, the case number, the mutation, a diff and the mutated file, and the
line that runs that case alone.

Usage: fuzz_prm.py EXE [--cases N] [--seed S] [--case K ...] [--np N] [--workers W] [--timeout T]
                       [--memory-limit GIB] [--work DIR] [--keep] [--source-dir DIR]
Case K of seed S is the same mutation on every machine (Python's random with a string seed),
so a failure is reproduced by: fuzz_prm.py EXE --seed S --case K.
"""
import argparse
import concurrent.futures
import difflib
import glob
import json
import os
import random
import re
import shutil
import signal
import subprocess
import sys
import tempfile
import time

# Scenes left out: the full-size 3D collapse takes 10 s to place its 512k points, and the two
# pre-failure scenes spend seconds in their FEM stage before the first MPM step (their bad
# input has tests of its own: tests/prm/bad/prefailure_*.prm); the long valley is a GPU scene
# of 20M points.
SKIPPED = {"granular_collapse_3d.prm", "slope_strength_reduction_2d.prm", "slope_strength_reduction_3d.prm",
           "runout_valley_3d.prm"}

# Values a number (or a whole value) is replaced by.
NUMBERS = ["0", "-1", "1", "-0", "1e308", "-1e308", "1e-308", "4.9e-324", "1e400", "nan", "-nan", "inf",
           "-inf", "99999999999999999999", "4294967296", "2147483648", "-2147483649", "18446744073709551615",
           "0.5", "1e9", "-1e9", "0x10", "1e", "--1", "1..2", ""]
WORDS = ["foo", "true", "false", "none", "yes", "0, 0, 0", ",", ";", "1, 2, 3, 4", "1,", ":", "0: soil",
         "Body 1", "\\", "#", "end", "subsection", "set", "=", "  "]
GARBAGE = ["\x00", "\x01", "\t", "\r", "\xff", "\u00e9", "\u2028", "{", "}", "=", "#", "\\", "\"", "'", "%", "$",
           "end", "\n", "subsection", " = ", "set", "\x7f", "\ufeff"]
INCLUDES = ["include /nonexistent/scene.prm", "include", "include ", "include /", "include /dev/null",
            "include {self}", "include {self_dir}"]
# Overrides that make every scene short; appended after the mutation, so later entries win.
OVERRIDES = """
subsection Solver
  set Maximum number of steps = 3
end
subsection Initial state
  set Equilibration maximum steps = 5
end
subsection Output
  set Directory = {out}
  set Progress interval = 0
end
"""
# Entries the "any entry" mutation leaves alone: the overrides set them, they turn on a stage
# that is slow by design (the pre-failure FEM; cuda without a build is a bad-input test), or
# they name folders to write into (Checkpoint/Directory = / would write into the root).
UNTOUCHED = ("Pre-failure analysis", "Backend", "Maximum number of steps", "Equilibration maximum steps",
             "Directory", "Progress interval")


def set_lines(lines):
    return [i for i, l in enumerate(lines) if re.match(r"\s*set\s+[^=]+=", l)]


class Mutator:
    def __init__(self, rng, entries, path):
        self.rng, self.entries, self.path = rng, entries, path

    def mutate(self, lines):
        """One mutation of the list of lines; returns (lines, description)."""
        # Weighted towards mutations that parse, so that most runs reach the program's own checks
        # and the steps; the structural ones mostly meet deal.II's parser.
        kinds = [self.delete_line] * 2 + [self.duplicate_line, self.swap_lines, self.truncate, self.cut_end,
                 self.add_end, self.garbage, self.include, self.value, self.empty_value] + \
            [self.number] * 4 + [self.selection] * 2 + [self.entry] * 6
        return self.rng.choice(kinds)(list(lines))

    def pick(self, lines, which=None):
        candidates = which if which is not None else [i for i, l in enumerate(lines) if l.strip()]
        return self.rng.choice(candidates) if candidates else None

    def delete_line(self, lines):
        i = self.pick(lines)
        if i is None:
            return lines, "nothing to delete"
        return lines[:i] + lines[i + 1:], f"deleted line {i + 1}: {lines[i].strip()!r}"

    def duplicate_line(self, lines):
        i = self.pick(lines)
        if i is None:
            return lines, "nothing to duplicate"
        return lines[:i + 1] + [lines[i]] + lines[i + 1:], f"duplicated line {i + 1}: {lines[i].strip()!r}"

    def swap_lines(self, lines):
        if len(lines) < 2:
            return lines, "too short to swap"
        i, j = sorted(self.rng.sample(range(len(lines)), 2))
        lines[i], lines[j] = lines[j], lines[i]
        return lines, f"swapped lines {i + 1} and {j + 1}"

    def number(self, lines):
        hits = [(i, m) for i in set_lines(lines)
                for m in re.finditer(r"[-+]?(\d+\.?\d*|\.\d+)([eE][-+]?\d+)?", lines[i].split("=", 1)[1])]
        if not hits:
            return self.value(lines)
        i, m = self.rng.choice(hits)
        head, tail = lines[i].split("=", 1)
        new = self.rng.choice(NUMBERS)
        lines[i] = head + "=" + tail[:m.start()] + new + tail[m.end():]
        return lines, f"line {i + 1}: number {m.group(0)!r} -> {new!r}: {lines[i].strip()!r}"

    def value(self, lines):
        i = self.pick(lines, set_lines(lines))
        if i is None:
            return lines, "no set line"
        new = self.rng.choice(WORDS + NUMBERS)
        lines[i] = lines[i].split("=", 1)[0] + "= " + new
        return lines, f"line {i + 1}: value -> {new!r}: {lines[i].strip()!r}"

    def empty_value(self, lines):
        i = self.pick(lines, set_lines(lines))
        if i is None:
            return lines, "no set line"
        lines[i] = lines[i].split("=", 1)[0] + "="
        return lines, f"line {i + 1}: value emptied: {lines[i].strip()!r}"

    def truncate(self, lines):
        text = "\n".join(lines)
        cut = self.rng.randrange(len(text) + 1)
        return text[:cut].split("\n"), f"file cut after character {cut} of {len(text)}"

    def cut_end(self, lines):
        i = self.pick(lines, [i for i, l in enumerate(lines) if l.strip() == "end"])
        if i is None:
            return self.delete_line(lines)
        return lines[:i] + lines[i + 1:], f"deleted the 'end' of line {i + 1}"

    def add_end(self, lines):
        i = self.rng.randrange(len(lines) + 1)
        return lines[:i] + ["end"] + lines[i:], f"inserted 'end' before line {i + 1}"

    def garbage(self, lines):
        text = "\n".join(lines)
        junk = "".join(self.rng.choice(GARBAGE) for _ in range(self.rng.randint(1, 4)))
        at = self.rng.randrange(len(text) + 1)
        return (text[:at] + junk + text[at:]).split("\n"), f"inserted {junk!r} at character {at}"

    def include(self, lines):
        line = self.rng.choice(INCLUDES).format(self=self.path, self_dir=os.path.dirname(self.path))
        i = self.rng.randrange(len(lines) + 1)
        return lines[:i] + [line] + lines[i:], f"inserted {line!r} before line {i + 1}"

    def selection(self, lines):
        """The value of a set line whose entry is a selection (or a bool): another option or a wrong one."""
        hits = []
        for i in set_lines(lines):
            name = lines[i].split("=", 1)[0].split(None, 1)[1].strip()
            options = [o for e in self.entries if e["name"] == name for o in e["options"]]
            if options:
                hits.append((i, options))
        if not hits:
            return self.value(lines)
        i, options = self.rng.choice(hits)
        new = self.rng.choice(options + [options[0].upper(), options[0] + " x", options[0][:-1], "|".join(options)])
        lines[i] = lines[i].split("=", 1)[0] + "= " + new
        return lines, f"line {i + 1}: selection -> {new!r}: {lines[i].strip()!r}"

    def entry(self, lines):
        """Any entry the program declares, set to an extreme value by its pattern (appended)."""
        e = self.rng.choice(self.entries)
        pattern = e["pattern"]
        # Mostly values the pattern accepts (its bounds and extremes inside them), so that the
        # program's own checks are reached, sometimes one it does not.
        bounds = re.match(r"\[(Integer range|Double) (\S+)\.\.\.(\S+) ", pattern)
        inside = []
        if bounds:
            kind = int if bounds.group(1) == "Integer range" else float
            low, high = (kind(v.replace("MAX_DOUBLE", "1.7976931348623157e308")) for v in bounds.group(2, 3))
            inside = [v for v in (["0", "1", "2", "1000000", "2147483647"] if kind is int else
                                  ["0", "1e-308", "1e-30", "1e-9", "0.999999", "1", "1e9", "1e30", "1e308"])
                      if low <= kind(v) <= high] + [repr(low), repr(high)]
        if e["options"]:
            new = self.rng.choice(e["options"] * 3 + ["", "foo"])
        elif "Integer" in pattern:
            new = self.rng.choice(inside * 2 + ["0", "-1", "1", "2147483647", "-2147483648", "1000000000", ""])
        elif "Double" in pattern:
            new = self.rng.choice(inside * 2 + ["0", "-1", "1e308", "1e-308", "nan", "inf", "1e30", "1e-30", "-0",
                                                ""])
        elif "List" in pattern or "Map" in pattern:
            new = self.rng.choice(["", "0", "1e308, 1e308, 1e308", "0, 0", "nan, nan", "-1, -1", "1, 2, 3, 4",
                                   "0: soil, 0", "0: foo", ",", "1e-308, 1e-308"])
        else:
            new = self.rng.choice(["", "foo", "/", "/nonexistent/x", ".", "a b"])
        # The declared set has one material, 'soil': take one the scene names instead.
        names = [n.strip() for l in lines if re.match(r"\s*set\s+Names\s*=", l) for n in l.split("=", 1)[1].split(",")]
        material = "Material " + self.rng.choice(names) if names else "Material soil"
        path = [material if s == "Material soil" else s for s in e["path"]]
        block = [f"subsection {s}" for s in path] + [f"set {e['name']} = {new}"] + ["end"] * len(path)
        path = "/".join(path + [e["name"]])
        return lines + block, f"appended {path} = {new!r}"


def declared_entries(exe, tmp):
    """Every entry of the 2D and 3D parameter sets: path, name, pattern, options of a selection/bool."""
    entries = {}
    for dim in (2, 3):
        text = subprocess.run([exe, "--print-parameters", str(dim), "json"], capture_output=True, text=True,
                              check=True, env=dict(os.environ, TMPDIR=tmp)).stdout
        def walk(node, path):
            for key, value in node.items():
                if isinstance(value, dict) and "pattern_description" in value:
                    if any(u in path + [key] for u in UNTOUCHED):
                        continue
                    pattern = value["pattern_description"]
                    options = []
                    m = re.match(r"\[Selection (.*) \]", pattern)
                    if m:
                        options = m.group(1).split("|")
                    elif pattern.startswith("[Bool"):
                        options = ["true", "false"]
                    entries[tuple(path + [key])] = dict(path=path, name=key, pattern=pattern, options=options)
                elif isinstance(value, dict):
                    walk(value, path + [key])
        walk(json.loads(text), [])
    return [entries[k] for k in sorted(entries)]


def make_case(seed, k, scenes, entries):
    rng = random.Random(f"{seed}:{k}")
    path = rng.choice(scenes)
    with open(path, encoding="utf-8") as f:
        original = f.read().split("\n")
    mutator = Mutator(rng, entries, path)
    lines, what = original, []
    for _ in range(rng.choice([1, 1, 1, 2, 3])):
        lines, description = mutator.mutate(lines)
        what.append(description)
    return path, original, lines, "; ".join(what)


def kill_session(session):
    """SIGKILL to every process of the session (mpirun's ranks may sit in process groups of their own),
    the leader (mpirun or the one rank) last, so that it can reap the others."""
    members = []
    for stat in glob.glob("/proc/[0-9]*/stat"):
        try:
            with open(stat) as f:
                if int(f.read().rsplit(")", 1)[1].split()[3]) == session:  # field 6 of stat, the session id
                    members.append(int(stat.split("/")[2]))
        except (OSError, ValueError, IndexError):
            pass
    for pid in sorted(members, key=lambda pid: pid == session):
        try:
            os.kill(pid, signal.SIGKILL)
        except OSError:
            pass
        if pid != session:
            time.sleep(0.05)


def run_case(exe, case_dir, text, timeout, memory_gib, np=1):
    """Runs dealii-mpm on the mutated text; returns (verdict or None if fine, status, output, seconds)."""
    os.makedirs(case_dir)
    prm = os.path.join(case_dir, "scene.prm")
    with open(prm, "w", encoding="utf-8", errors="surrogateescape") as f:
        f.write(text + OVERRIDES.format(out=os.path.join(case_dir, "output")))
    tmp = os.path.join(case_dir, "tmp")  # Open MPI's session folder, one per run
    os.makedirs(tmp)
    start = time.monotonic()
    # The limits through the shell (preexec_fn is not safe beside threads); exec keeps the status.
    # The address-space limit makes a run that wants more memory stop with bad_alloc instead of
    # taking the machine's (none under ASan, whose shadow memory is terabytes of address space).
    limit = f"ulimit -v {memory_gib << 20} && " if memory_gib else ""
    launcher = ["mpirun", "--oversubscribe", "-np", str(np)] if np > 1 else []
    command = ["/bin/sh", "-c", limit + 'ulimit -c 0 && exec "$@"', "sh"] + launcher + [exe, prm]
    env = dict(os.environ, TMPDIR=tmp, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")
    process = subprocess.Popen(command, cwd=case_dir, stdin=subprocess.DEVNULL, stdout=subprocess.PIPE,
                               stderr=subprocess.PIPE, env=env, start_new_session=True)
    try:
        out, err = process.communicate(timeout=timeout)
        status = process.returncode
    except subprocess.TimeoutExpired:
        kill_session(process.pid)
        out, err = process.communicate()
        status = None
    seconds = time.monotonic() - start
    out, err = out.decode(errors="replace"), err.decode(errors="replace")
    output = out[-3000:] + ("\n--- stderr ---\n" + err[-4000:] if err else "")
    with open(os.path.join(case_dir, "log.txt"), "w") as f:
        f.write(f"{out}\n--- stderr ---\n{err}\n--- exit status: {status}\n")
    if status is None:
        return f"hang: still running after {timeout} s", status, output, seconds
    if status < 0:
        return f"killed by signal {-status} ({signal.Signals(-status).name})", status, output, seconds
    if "terminate called" in err or "terminate called" in out:
        return "uncaught exception (terminate called)", status, output, seconds
    if status >= 128:
        return f"exit status {status} (>= 128)", status, output, seconds
    if status != 0 and "dealii-mpm: error" not in err:
        return f"exit status {status} without a 'dealii-mpm: error' message on stderr", status, output, seconds
    return None, status, output, seconds


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("exe")
    parser.add_argument("--cases", type=int, default=300)
    parser.add_argument("--seed", default="17")
    parser.add_argument("--case", type=int, action="append", help="run only this case (repeatable)")
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--np", type=int, default=1, help="MPI ranks of each run (mpirun above 1)")
    parser.add_argument("--timeout", type=float, default=10)
    parser.add_argument("--work", help="folder of the runs (default: a new temporary folder)")
    parser.add_argument("--memory-limit", type=int, default=4, help="address space of a run in GiB (0: none)")
    parser.add_argument("--keep", action="store_true", help="keep the folders of passing cases too")
    parser.add_argument("--source-dir", default=os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", ".."))
    args = parser.parse_args()

    exe = os.path.abspath(args.exe)
    source = os.path.abspath(args.source_dir)
    scenes = sorted(p for p in glob.glob(os.path.join(source, "prm", "*.prm")) +
                    glob.glob(os.path.join(source, "tests", "prm", "*.prm")) if os.path.basename(p) not in SKIPPED)
    if args.work:
        shutil.rmtree(args.work, ignore_errors=True)
        os.makedirs(args.work)
        work = args.work
    else:
        work = tempfile.mkdtemp(prefix="fuzz-prm-")
    entries = declared_entries(exe, work)
    ids = args.case if args.case else range(args.cases)
    cases = {k: make_case(args.seed, k, scenes, entries) for k in ids}
    print(f"fuzz_prm: seed {args.seed}, {len(cases)} cases on {args.np} rank(s) over {len(scenes)} scenes, {len(entries)} entries, "
          f"{args.workers} workers, {args.timeout:g} s each, in {work}", flush=True)

    start = time.monotonic()
    failures, statuses, slowest, out_of_memory = [], {}, (0, None), []
    with concurrent.futures.ThreadPoolExecutor(args.workers) as pool:
        futures = {pool.submit(run_case, exe, os.path.join(work, f"case-{k:04d}"), "\n".join(cases[k][2]),
                               args.timeout, args.memory_limit, args.np): k for k in cases}
        for future in concurrent.futures.as_completed(futures):
            k = futures[future]
            verdict, status, output, seconds = future.result()
            statuses[status] = statuses.get(status, 0) + 1
            slowest = max(slowest, (seconds, k))
            if verdict:
                failures.append((k, verdict, output))
            elif "bad_alloc" in output:
                out_of_memory.append(k)  # a clean exit, but no guard named the entry first
            elif not args.keep:
                shutil.rmtree(os.path.join(work, f"case-{k:04d}"), ignore_errors=True)

    for n, (k, verdict, output) in enumerate(sorted(failures)):
        path, original, lines, what = cases[k]
        print(f"\n==== FAILED case {k} (seed {args.seed}): {verdict}")
        print(f"scene:    {os.path.relpath(path, source)}")
        print(f"mutation: {what}")
        print(f"again:    /usr/bin/python3 {os.path.relpath(__file__, source)} {args.exe} --seed {args.seed} "
              f"--case {k} --np {args.np} --keep")
        print(f"files:    {os.path.join(work, f'case-{k:04d}')}/scene.prm (with the overrides)")
        print("".join(difflib.unified_diff([l + "\n" for l in original], [l + "\n" for l in lines],
                                           "original", "mutated", n=1)), end="")
        print("---- output (tail) ----\n" + output.rstrip())
        if n < 3:
            print("---- mutated file ----\n" + "\n".join(lines))
    if out_of_memory:
        print(f"\nnote: cases {' '.join(map(str, sorted(out_of_memory)))} stopped with std::bad_alloc at the "
              f"{args.memory_limit} GiB limit of a run (clean, but no entry named)")
    print(f"\nfuzz_prm: {len(cases)} cases in {time.monotonic() - start:.0f} s (slowest: case {slowest[1]}, "
          f"{slowest[0]:.1f} s); exit statuses "
          + ", ".join(f"{'timeout' if s is None else s}: {c}" for s, c in sorted(statuses.items(), key=str))
          + f"; {len(failures)} failed" + (": cases " + " ".join(str(k) for k, _, _ in sorted(failures))
                                            if failures else ""))
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
