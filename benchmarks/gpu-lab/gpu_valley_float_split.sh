#!/usr/bin/env bash
# On the GPU machine: splits the causes of the long valley's blow-up in float (doc/performance.md,
# "The long valley"). The same scene in a valley 2 m long (the front stays below 1.8 m to 1.2 s, so
# the box changes nothing but the nodes' numbering) to t = 0.85 s, in float with every node and in
# float with nodes near the material; RUNS adds others: all-double, and the valley 400 m long near the
# material in float (long; long-cfl with a CFL number of 0.4999 or CFL: another trajectory without an
# output) and double (long-double). No field written (OUTPUT_INTERVAL, default 0, still
# makes the steps land on the output times); the history kept.
#   BIN=dir [RUNS='all near'] [OUTPUT_INTERVAL=s] [TAG=suffix of the run folders] bash benchmarks/gpu-lab/gpu_valley_float_split.sh
set -u -o pipefail
ROOT=$(cd "$(dirname "$0")/../.." && pwd)
OUT=${OUT:-$ROOT/out}
for run in ${RUNS:-all near}; do
  cfl=0.5
  case $run in
    all) nodes=all precision=float length=2 ;;
    near) nodes='near material' precision=float length=2 ;;
    all-double) nodes=all precision=double length=2 ;;
    long) nodes='near material' precision=float length=400 ;;
    long-double) nodes='near material' precision=double length=400 ;;
    long-cfl) nodes='near material' precision=float length=400 cfl=${CFL:-0.4999} ;;
    *) echo "unknown run $run (all, near, all-double, long, long-double, long-cfl)"; exit 2 ;;
  esac
  extra=$(printf '%s\n' "subsection Grid" "  set Upper corner = $length, 1, 0.6" "  set Nodes = $nodes" "end" \
    "subsection Backend" "  set Precision = $precision" "end" "subsection Solver" "  set End time = 0.85" "  set CFL number = $cfl" "end" \
    "subsection Output" "  set Output interval = ${OUTPUT_INTERVAL:-0}" "  set Write particles = false" \
    "  set Write grid fields = false" "end")
  OUT=$OUT/$run${TAG:-} LIMIT=${LIMIT:-280} EXTRA="$extra" bash "$ROOT/benchmarks/gpu-lab/gpu_runout_valley.sh"
  /usr/bin/env python3 - "$OUT/$run${TAG:-}/history.csv" <<'PY' || true
import csv, sys
rows = list(csv.DictReader(open(sys.argv[1])))
keys = rows[0].keys()
for r in rows[::4] + rows[-3:]:
    print(' '.join(f"{k}={r[k]}" for k in keys if k in ('time', 'dt', 'step', 'kinetic_energy', 'max_x', 'max_z', 'n_removed')))
PY
done
