#!/usr/bin/env bash
# On the GPU machine (deal.II runtime unpacked, `. /opt/dl/dl-env.sh`): the long-valley run-out
# (prm/runout_valley_3d.prm: 20,000,000 points, a lattice of 1.92e9 cells, Grid/Nodes = near material)
# with Backend = cuda, to its End time or to LIMIT seconds. Wall time by the shell clock, device
# memory at its peak over the idle reading (nvidia-smi every 200 ms), the log's summary lines and
# the history (extent of the material, kinetic energy) into $OUT (or ./out).
#   BIN=dir [LIMIT=560] [EXTRA='prm lines'] bash benchmarks/gpu-lab/gpu_runout_valley.sh
set -u -o pipefail
ROOT=$(cd "$(dirname "$0")/../.." && pwd)
BIN=$(cd "${BIN:-$ROOT/build-cuda/dev}" && pwd)
OUT=${OUT:-$ROOT/out}
LIMIT=${LIMIT:-560}
mkdir -p "$OUT"
. "$ROOT/scripts/dev/gpu_unpack_build.sh"
prepare_build "$BIN" "$OUT"
idle=$(nvidia-smi --query-gpu=memory.used --format=csv,noheader,nounits | head -1)
prm=/tmp/valley.prm
cp "$ROOT/prm/runout_valley_3d.prm" "$prm"
printf '%s\n' "subsection Output" "  set Directory = /tmp/valley" "  set Progress interval = 20" "end" >>"$prm"
[ -n "${EXTRA:-}" ] && printf '%s\n' "$EXTRA" >>"$prm"
nvidia-smi --query-gpu=memory.used --format=csv,noheader,nounits -lms 200 >/tmp/valley.mem &
sampler=$!
t0=$(date +%s.%N)
timeout "$LIMIT" "$BIN/dealii-mpm" "$prm" >"$OUT/valley.log" 2>&1 &
runner=$!
sleep 1
hwm=0 # the program's peak resident host memory (VmHWM), read while it runs
while kill -0 $runner 2>/dev/null; do
  pid=$(pgrep -P $runner | head -1)
  [ -n "$pid" ] && h=$(awk '/VmHWM/ {print $2}' /proc/$pid/status 2>/dev/null) && [ -n "$h" ] && hwm=$h
  sleep 1
done
wait $runner
rc=$?
t1=$(date +%s.%N)
kill $sampler 2>/dev/null; wait $sampler 2>/dev/null
peak=$(sort -n /tmp/valley.mem | tail -1)
{
  printf 'valley rc=%d wall %.1f s, device memory %d MiB over idle (%d MiB idle), host peak %d MiB\n' $rc \
    "$(awk "BEGIN{print $t1 - $t0}")" $((peak - idle)) "$idle" $((hwm / 1024))
  grep -E "done, t =|set-up|nodes near the material|loop on rank|output:|points? left" "$OUT/valley.log"
  free -g | head -2
} | tee "$OUT/summary.txt"
cp /tmp/valley/history.csv "$OUT/history.csv" 2>/dev/null
tail -5 "$OUT/valley.log"
exit 0
