#!/bin/bash
# Grid/Nodes = near material on 2 ranks (CPU): memory follows the material, not the box. The
# reduced V3 collapse (collapse_small_2d.prm) to 0.05 s in its own box (120 x 24 cells) and in a
# box 64x longer and 64x taller (4096x the area, 11.8M cells, the extra space empty), both with
# Resources/Memory limit = 2 GB for the whole run: the big box must pass the memory guard (an
# estimate of deal.II's grid over the whole box, 16 GB, refuses it), give the compact box's
# particles to 1e-10 (the partitions may differ: round-off) and peak at most 1.5x the compact box's
# resident memory on its largest rank (lookups over the lattice, about 20 bytes a cell on each
# rank, took it to 2.5x: 470 MB against 190 MB, seen 2026-12-05).
#   near_material_large_box.sh EXE OUTDIR
set -eu
exe=$1 out=$2
here=$(cd "$(dirname "$0")" && pwd)
mkdir -p "$out"
# The largest resident set of the ranks of one run (getrusage of the waited-for descendants), in KB.
# peak_of LOG COMMAND...: prints the command's status and that peak; its output goes to LOG.
peak_of() {
  /usr/bin/python3 -c "
import resource, subprocess, sys
with open(sys.argv[1], 'w') as log:
    rc = subprocess.run(sys.argv[2:], stdout=log, stderr=subprocess.STDOUT).returncode
print(rc, resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss)" "$@"
}
run() { # NAME [prm lines...]
  local name=$1
  shift
  peak_of "$out/$name.log" bash "$here/run_scene.sh" "$exe" "$here/collapse_small_2d.prm" "$out/$name" 2 \
    "subsection Grid" "  set Nodes = near material" "end" \
    "subsection Solver" "  set End time = 0.05" "end" \
    "subsection Resources" "  set Memory limit = 2" "end" \
    "subsection Output" "  set Write particle table = true" "  set Output interval = 0.05" "end" "$@"
}
read -r rc_own peak_own < <(run own)
read -r rc_big peak_big < <(run big "subsection Grid" "  set Upper corner = 38.4, 7.68" "end")
echo "peak resident memory of a rank: own box $peak_own KB, 4096x box $peak_big KB"
[ "$rc_own" = 0 ] || { cat "$out/own.log"; echo "FAILED: the run in its own box failed"; exit 1; }
[ "$rc_big" = 0 ] || { cat "$out/big.log"; echo "FAILED: the run in the 4096x box failed"; exit 1; }
/usr/bin/python3 "$here/compare_np.py" "$out/own" "$out/big" --rtol 1e-10
/usr/bin/python3 -c "
import sys
own, big = $peak_own, $peak_big
ok = big <= 1.5 * own
print(('' if ok else 'FAILED: ') + 'the 4096x box peaks at %.2fx the own box (at most 1.5)' % (big / own))
sys.exit(0 if ok else 1)"
