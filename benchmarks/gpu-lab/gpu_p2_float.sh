#!/usr/bin/env bash
# On the GPU machine (deal.II runtime unpacked, `. /opt/dl/dl-env.sh`): P2 as it is (prm/granular_collapse_3d.prm,
# Backend = cuda, output every 0.1 s) with Backend/Precision = double and float, in turn, ROUNDS times: wall
# time by the shell clock, the program's own, the engine's ms per step; then the deposit of the last run of
# each (scripts/deposit_3d.py: toe, top-left height, slope).
#   BIN=dir [ROUNDS=2] bash benchmarks/gpu-lab/gpu_p2_float.sh     (dir: dealii-mpm, libdealii-mpm.so*, libdeal.ii*.xz)
set -u -o pipefail
ROOT=$(cd "$(dirname "$0")/../.." && pwd)
BIN=$(cd "${BIN:?BIN: the folder with the CUDA build of dealii-mpm}" && pwd)
OUT=${OUT:-$ROOT/out}
mkdir -p "$OUT"
. "$ROOT/scripts/dev/gpu_unpack_build.sh"
prepare_build "$BIN" "$OUT"
py=/usr/bin/python3; "$py" -c "import numpy" 2>/dev/null || py=python3
for precision in double float; do
  prm=/tmp/p2_$precision.prm
  cp "$ROOT/prm/granular_collapse_3d.prm" "$prm"
  printf '%s\n' "subsection Output" "  set Directory = /tmp/p2-$precision" "  set Progress interval = 0" "end" \
    "subsection Backend" "  set Backend = cuda" "  set Precision = $precision" "end" >>"$prm"
done
for round in $(seq "${ROUNDS:-2}"); do
  for precision in double float; do
    rm -rf /tmp/p2-$precision
    t0=$(date +%s.%N)
    "$BIN/dealii-mpm" /tmp/p2_$precision.prm >"$OUT/p2_${precision}_$round.log" 2>&1
    rc=$?
    t1=$(date +%s.%N)
    log=$OUT/p2_${precision}_$round.log
    printf 'round %d %-6s rc=%d shell %.2f s | %s | %s | %s\n' "$round" $precision $rc "$(awk "BEGIN{print $t1 - $t0}")" \
      "$(grep -oE 'backend [a-z]+( in float)?' "$log" | head -1)" \
      "$(grep -oE 'done, t = .* s wall' "$log" | tail -1)" "$(grep -oE 'engine step [0-9.e-]+' "$log" | tail -1)"
  done
done | tee "$OUT/p2_float_times.txt"
for precision in double float; do
  echo "== deposit, $precision: $("$py" "$ROOT/scripts/deposit_3d.py" /tmp/p2-$precision 2>&1 | tr '\n' ' ' | cut -c1-600)"
done | tee -a "$OUT/p2_float_times.txt"
