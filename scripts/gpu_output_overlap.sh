#!/usr/bin/env bash
# On the GPU machine (deal.II runtime unpacked, `. /opt/dl/dl-env.sh`): P2 (prm/granular_collapse_3d.prm) with
# Backend = cuda, the outputs' point downloads overlapped with the steps (the default) and waited for
# (MPM_OUTPUT_OVERLAP=0), in turn, ROUNDS times; each with the shell clock, the program's wall time, the timer's
# output row, the wait for the output threads and the engine's ms per step; then the deposit of the last run of
# each (scripts/deposit_3d.py), which should agree to the spread of two runs (the GPU's atomics sum in another
# order from run to run).
#   BIN=dir [ROUNDS=3] bash scripts/gpu_output_overlap.sh    (dir: dealii-mpm, libdealii-mpm.so*)
set -u -o pipefail
ROOT=$(cd "$(dirname "$0")/.." && pwd)
BIN=$(cd "${BIN:?BIN: the folder with the CUDA build of dealii-mpm}" && pwd)
OUT=${OUT:-$ROOT/out}
mkdir -p "$OUT"
. "$ROOT/scripts/gpu_unpack_build.sh"
prepare_build "$BIN" "$OUT"
py=/usr/bin/python3; "$py" -c "import numpy" 2>/dev/null || py=python3
for way in overlap wait; do
  cp "$ROOT/prm/granular_collapse_3d.prm" /tmp/o_$way.prm
  printf '%s\n' "subsection Output" "  set Directory = /tmp/o-$way" "  set Progress interval = 0" "end" \
    "subsection Backend" "  set Backend = cuda" "end" >>/tmp/o_$way.prm
done
for round in $(seq "${ROUNDS:-3}"); do
  for way in overlap wait; do
    overlap=1
    [ $way = wait ] && overlap=0
    rm -rf /tmp/o-$way
    log=$OUT/p2_${way}_$round.log
    t0=$(date +%s.%N)
    MPM_OUTPUT_OVERLAP=$overlap "$BIN/dealii-mpm" /tmp/o_$way.prm >"$log" 2>&1
    rc=$?
    t1=$(date +%s.%N)
    printf 'round %d %-7s rc=%d shell %.2f s | %s | %s | %s | %s\n' "$round" $way $rc \
      "$(awk "BEGIN{print $t1 - $t0}")" "$(grep -oE 'done, t = .* s wall' "$log" | tail -1)" \
      "$(grep -E '^\| output ' "$log" | tr -s ' ' | head -1)" "$(grep -oE 'the run waited [0-9.e-]+ s' "$log" | tail -1)" \
      "$(grep -oE 'engine step [0-9.e-]+' "$log" | tail -1)"
  done
done | tee "$OUT/output_overlap_times.txt"
for way in overlap wait; do
  echo "== deposit, $way: $("$py" "$ROOT/scripts/deposit_3d.py" /tmp/o-$way 2>&1 | tr '\n' ' ' | cut -c1-400)"
done | tee -a "$OUT/output_overlap_times.txt"
