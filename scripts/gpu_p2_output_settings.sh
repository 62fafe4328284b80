#!/usr/bin/env bash
# On the GPU machine (deal.II runtime unpacked, `. /opt/dl/dl-env.sh`): what P2's output settings cost. P2
# (prm/granular_collapse_3d.prm, Backend = cuda) as it is (`k8`: Output/Files per rank = 8), with 16 pieces per
# output (`k16`), with 4 (`k4`), and with 8 pieces of the position, velocity and stress only (`fields`: Output/
# Particle fields = velocity, stress), in turn, ROUNDS times; each with the program's wall time, the timer's
# output row and the wait at the end for the last output's files. `k8-noyield` and `k16-noyield`: 8 and 16 pieces
# with the output threads at the steps' priority (MPM_OUTPUT_YIELD=0).
#   BIN=dir [ROUNDS=2] [WAYS="k8 k16 k4 fields"] bash scripts/gpu_p2_output_settings.sh
# (dir: dealii-mpm, libdealii-mpm.so*)
set -u -o pipefail
ROOT=$(cd "$(dirname "$0")/.." && pwd)
BIN=$(cd "${BIN:?BIN: the folder with the CUDA build of dealii-mpm}" && pwd)
OUT=${OUT:-$ROOT/out}
mkdir -p "$OUT"
. "$ROOT/scripts/gpu_unpack_build.sh"
prepare_build "$BIN" "$OUT"
ways=${WAYS:-k8 k16 k4 fields}
for way in $ways; do
  case $way in
    k8 | k8-noyield) extra=("  set Files per rank = 8") ;;
    k16 | k16-noyield) extra=("  set Files per rank = 16") ;;
    k4) extra=("  set Files per rank = 4") ;;
    fields) extra=("  set Files per rank = 8" "  set Particle fields = velocity, stress") ;;
  esac
  cp "$ROOT/prm/granular_collapse_3d.prm" /tmp/s_$way.prm
  printf '%s\n' "subsection Output" "  set Directory = /tmp/s-$way" "  set Progress interval = 0" "${extra[@]}" "end" \
    "subsection Backend" "  set Backend = cuda" "end" >>/tmp/s_$way.prm
done
for round in $(seq "${ROUNDS:-2}"); do
  for way in $ways; do
    rm -rf /tmp/s-$way
    log=$OUT/p2_${way}_$round.log
    t0=$(date +%s.%N)
    yield=1
    case $way in *-noyield) yield=0 ;; esac
    MPM_OUTPUT_YIELD=$yield "$BIN/dealii-mpm" /tmp/s_$way.prm >"$log" 2>&1
    rc=$?
    t1=$(date +%s.%N)
    printf 'round %d %-6s rc=%d shell %.2f s | %s | %s | %s | files %s\n' "$round" $way $rc \
      "$(awk "BEGIN{print $t1 - $t0}")" "$(grep -oE 'done, t = .* s wall' "$log" | tail -1)" \
      "$(grep -E '^\| output ' "$log" | tr -s ' ' | head -1)" \
      "$(grep -E '^\| output: waiting' "$log" | tr -s ' ' | head -1)" "$(du -sh /tmp/s-$way | cut -f1)"
  done
done | tee "$OUT/output_settings_times.txt"
