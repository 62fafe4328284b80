#!/usr/bin/env bash
# On the GPU machine (deal.II runtime unpacked, `. /opt/dl/dl-env.sh`): P2 (prm/granular_collapse_3d.prm) and V3 2D
# (prm/granular_collapse_2d.prm) with Backend = cuda in three ways, in turn, ROUNDS times: `graphs` (Backend/Queue
# steps = true, the default: steps queued, replayed as CUDA graphs), `queued` (the same with MPM_CUDA_GRAPHS=0)
# and `off` (Queue steps = false); each with the shell clock, the program's wall time, the engine's ms per step
# and the step count; then the deposits of the last run of each (scripts/deposit_3d.py, scripts/deposit.py),
# which should agree to the spread of two runs (the GPU's atomics sum in a different order from run to run).
#   BIN=dir [ROUNDS=3] [SCENES="3d 2d"] bash benchmarks/gpu-lab/gpu_queue_steps.sh    (dir: dealii-mpm, libdealii-mpm.so*)
set -u -o pipefail
ROOT=$(cd "$(dirname "$0")/../.." && pwd)
BIN=$(cd "${BIN:?BIN: the folder with the CUDA build of dealii-mpm}" && pwd)
OUT=${OUT:-$ROOT/out}
mkdir -p "$OUT"
. "$ROOT/scripts/dev/gpu_unpack_build.sh"
prepare_build "$BIN" "$OUT"
py=/usr/bin/python3; "$py" -c "import numpy" 2>/dev/null || py=python3
scenes=${SCENES:-3d 2d}
for scene in $scenes; do
  for way in graphs queued off; do
    queue=true
    [ $way = off ] && queue=false
    cp "$ROOT/prm/granular_collapse_$scene.prm" /tmp/q_${scene}_$way.prm
    printf '%s\n' "subsection Output" "  set Directory = /tmp/q-$scene-$way" "  set Progress interval = 0" "end" \
      "subsection Backend" "  set Backend = cuda" "  set Queue steps = $queue" "end" >>/tmp/q_${scene}_$way.prm
  done
done
for round in $(seq "${ROUNDS:-3}"); do
  for scene in $scenes; do
    for way in graphs queued off; do
      graphs=1
      [ $way = queued ] && graphs=0
      rm -rf /tmp/q-$scene-$way
      log=$OUT/${scene}_${way}_$round.log
      t0=$(date +%s.%N)
      MPM_CUDA_GRAPHS=$graphs "$BIN/dealii-mpm" /tmp/q_${scene}_$way.prm >"$log" 2>&1
      rc=$?
      t1=$(date +%s.%N)
      printf 'round %d %s %-6s rc=%d shell %.2f s | %s | %s\n' "$round" "$scene" $way $rc \
        "$(awk "BEGIN{print $t1 - $t0}")" "$(grep -oE 'done, t = .* s wall' "$log" | tail -1)" \
        "$(grep -oE 'engine step [0-9.e-]+' "$log" | tail -1)"
    done
  done
done | tee "$OUT/queue_times.txt"
for scene in $scenes; do
  for way in graphs queued off; do
    if [ "$scene" = 3d ]; then
      d=$("$py" "$ROOT/scripts/deposit_3d.py" /tmp/q-$scene-$way 2>&1)
    else
      d=$("$py" "$ROOT/scripts/deposit.py" /tmp/q-$scene-$way 2>&1)
    fi
    echo "== deposit, $scene, $way: $(echo "$d" | tr '\n' ' ' | cut -c1-400)"
  done
done | tee -a "$OUT/queue_times.txt"
