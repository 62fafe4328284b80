#!/bin/bash
# Runs one scene on several numbers of MPI ranks, each into OUTDIR/npN, with the
# full-precision particle table on (for compare_np.py) and overrides appended.
# Usage: run_np.sh EXE PRM OUTDIR "1 2 4" [override lines...]   Exits non-zero if a run fails.
set -eu
exe=$1 prm=$2 out=$3 nps=$4
shift 4
here=$(dirname "$0")
for np in $nps; do
  start=$(date +%s.%N)
  bash "$here/run_scene.sh" "$exe" "$prm" "$out/np$np" "$np" \
    "subsection Output" "  set Write particle table = true" "end" "$@" > "$out-np$np.log" 2>&1 ||
    { cat "$out-np$np.log"; echo "FAILED: the run on $np rank(s) failed"; exit 1; }
  grep -E "^  (MPI|repartitioned)" "$out-np$np.log" | sed "s/^/np $np:/" || true
  echo "np $np: $(awk "BEGIN{print $(date +%s.%N) - $start}") s wall"
done
