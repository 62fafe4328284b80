#!/usr/bin/env bash
# On the GPU machine (deal.II runtime unpacked, `. /opt/dl/dl-env.sh`): what P2's output costs. P2
# (prm/granular_collapse_3d.prm, Backend = cuda) in the ways WAYS names, in turn, ROUNDS times; each with the
# shell clock, the program's wall time, the timer's output row, the wait at the end for the last output's files,
# the engine's ms per step and the size of the output folder; then the deposit of each way's last run
# (scripts/deposit_3d.py), which should agree to the spread of two runs (the GPU's atomics sum in another order
# from run to run). The ways:
#   k8: the prm as it is (Output/Files per rank = 8); k16, k4: 16 and 4 pieces per output;
#   fields: 8 pieces of the position, velocity and stress only (Output/Particle fields = velocity, stress);
#   k8-wait: each output waits for its points' download (MPM_OUTPUT_OVERLAP=0);
#   k8-noyield, k16-noyield: the output threads at the steps' priority (MPM_OUTPUT_YIELD=0).
#   BIN=dir [ROUNDS=2] [WAYS="k8 k16 k4 fields"] bash benchmarks/gpu-lab/gpu_p2_output_settings.sh
# (dir: dealii-mpm, libdealii-mpm.so*)
set -u -o pipefail
ROOT=$(cd "$(dirname "$0")/../.." && pwd)
BIN=$(cd "${BIN:?BIN: the folder with the CUDA build of dealii-mpm}" && pwd)
OUT=${OUT:-$ROOT/out}
mkdir -p "$OUT"
. "$ROOT/scripts/dev/gpu_unpack_build.sh"
prepare_build "$BIN" "$OUT"
py=/usr/bin/python3; "$py" -c "import numpy" 2>/dev/null || py=python3
ways=${WAYS:-k8 k16 k4 fields}
for way in $ways; do
  case $way in
    k8 | k8-wait | k8-noyield) extra=("  set Files per rank = 8") ;;
    k16 | k16-noyield) extra=("  set Files per rank = 16") ;;
    k4) extra=("  set Files per rank = 4") ;;
    fields) extra=("  set Files per rank = 8" "  set Particle fields = velocity, stress") ;;
    *) echo "unknown way '$way' (k8 k16 k4 fields k8-wait k8-noyield k16-noyield)"; exit 2 ;;
  esac
  cp "$ROOT/prm/granular_collapse_3d.prm" /tmp/s_$way.prm
  printf '%s\n' "subsection Output" "  set Directory = /tmp/s-$way" "  set Progress interval = 0" "${extra[@]}" "end" \
    "subsection Backend" "  set Backend = cuda" "end" >>/tmp/s_$way.prm
done
for round in $(seq "${ROUNDS:-2}"); do
  for way in $ways; do
    rm -rf /tmp/s-$way
    log=$OUT/p2_${way}_$round.log
    overlap=1 yield=1
    case $way in *-wait) overlap=0 ;; *-noyield) yield=0 ;; esac
    t0=$(date +%s.%N)
    MPM_OUTPUT_OVERLAP=$overlap MPM_OUTPUT_YIELD=$yield "$BIN/dealii-mpm" /tmp/s_$way.prm >"$log" 2>&1
    rc=$?
    t1=$(date +%s.%N)
    printf 'round %d %-11s rc=%d shell %.2f s | %s | %s | %s | %s | files %s\n' "$round" $way $rc \
      "$(awk "BEGIN{print $t1 - $t0}")" "$(grep -oE 'done, t = .* s wall' "$log" | tail -1)" \
      "$(grep -E '^\| output ' "$log" | tr -s ' ' | head -1)" \
      "$(grep -E '^\| output: waiting' "$log" | tr -s ' ' | head -1)" \
      "$(grep -oE 'engine step [0-9.e-]+' "$log" | tail -1)" "$(du -sh /tmp/s-$way | cut -f1)"
  done
done | tee "$OUT/output_settings_times.txt"
for way in $ways; do
  echo "== deposit, $way: $("$py" "$ROOT/scripts/deposit_3d.py" /tmp/s-$way 2>&1 | tr '\n' ' ' | cut -c1-400)"
done | tee -a "$OUT/output_settings_times.txt"
