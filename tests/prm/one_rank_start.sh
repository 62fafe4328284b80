#!/bin/bash
# One rank starts stepping while deal.II builds the grid and the handler on a thread
# (simulator.cc); two ranks build them first. On collapse_small_2d.prm in a domain 80 times
# taller (230,400 cells: on the development VM the grid thread took 0.46 s against the
# engine's 0.03 s, and the first output, after 17 steps, waited for it), with outputs every
# 0.002 s and history rows every 5 steps, so that both fall due before the grid exists.
# How many steps run beside the thread depends on the machine (the log says it; a fast one
# may run none). Asserts:
#  - the one-rank log reports the grid thread (the path was taken) and how many steps ran beside it;
#  - both runs have the same particle and grid records (t = 0 first);
#  - the t = 0 grid file, written once the grid exists, has zero nodal fields (no step yet);
#  - the particle tables at t = 0, at the first output after it and at the end agree with
#    two ranks' to 1e-10 (round-off of the sum order only).
# Usage: one_rank_start.sh EXE SOURCE_DIR OUTDIR
set -eu
exe=$1 src=$2 out=$3 here=$(dirname "$0")
bash "$here/run_np.sh" "$exe" "$here/collapse_small_2d.prm" "$out" "1 2" \
  "subsection Grid" "  set Upper corner = 0.6, 9.6" "end" \
  "subsection Solver" "  set End time = 0.01" "end" \
  "subsection Output" "  set Output interval = 0.002" "  set History every n steps = 5" "end"
grep "built on a thread" "$out-np1.log" || { echo "FAILED: the one-rank run did not report its grid thread"; exit 1; }
/usr/bin/python3 - "$out/np1" "$out/np2" "$src/scripts" <<'PY'
import sys
sys.path.insert(0, sys.argv[3])
import numpy as np
import mpm_results as r
one, two = sys.argv[1], sys.argv[2]
ok = True
for name in ("particles", "grid"):
    a, b = [t for t, _ in r.pvd_records(one, name)], [t for t, _ in r.pvd_records(two, name)]
    if a != b or a[0] != 0 or len(a) != 6:
        print(f"FAILED: {name} records at {a} on one rank, {b} on two (expected 0, 0.002, ..., 0.01)"); ok = False
grid0 = r.read_pvtu(one, r.pvd_records(one, "grid")[0][1])
nodal = [k for k in grid0 if k.startswith("nodal_")]
largest = max(float(np.abs(grid0[k]).max()) for k in nodal)
print(f"t = 0 grid file on one rank: fields {nodal}, largest |value| {largest}")
if len(nodal) < 3 or largest != 0:
    print("FAILED: the t = 0 grid file must have zero nodal mass and velocity"); ok = False
sys.exit(0 if ok else 1)
PY
for t in 0 0.002; do
  /usr/bin/python3 "$here/compare_np.py" "$out/np1" "$out/np2" --rtol 1e-10 --time $t
done
/usr/bin/python3 "$here/compare_np.py" "$out/np1" "$out/np2" --rtol 1e-10
