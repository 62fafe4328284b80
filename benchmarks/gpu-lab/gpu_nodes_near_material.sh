#!/usr/bin/env bash
# On the GPU machine (deal.II runtime unpacked, `. /opt/dl/dl-env.sh`): Grid/Nodes = near material
# with Backend = cuda. Runs the GPU ctest script tests/prm/nodes_near_material_cuda.sh, then P2
# (prm/granular_collapse_3d.prm, 512,000 points, 1 s, output every 0.1 s) in its own box with every
# node and with nodes near the material, and in a box 4x longer and 2x wider (the extra space
# empty) both ways; wall time by the shell clock and the device memory in use at its peak
# (nvidia-smi every 100 ms, minus the idle reading). Results and logs into $OUT (or ./out).
#   BIN=dir bash benchmarks/gpu-lab/gpu_nodes_near_material.sh   (dir: dealii-mpm, libdealii-mpm.so*, libdeal.ii.so.9.4.1.xz)
set -u -o pipefail
ROOT=$(cd "$(dirname "$0")/../.." && pwd)
BIN=$(cd "${BIN:-$ROOT/build-cuda/dev}" && pwd)
OUT=${OUT:-$ROOT/out}
mkdir -p "$OUT"
. "$ROOT/scripts/dev/gpu_unpack_build.sh"
prepare_build "$BIN" "$OUT"
idle=$(nvidia-smi --query-gpu=memory.used --format=csv,noheader,nounits | head -1)

echo "== GPU test: near material against every node" | tee -a "$OUT/summary.txt"
bash "$ROOT/tests/prm/nodes_near_material_cuda.sh" "$BIN/dealii-mpm" /tmp/near-cuda 2>&1 | tail -8 | tee -a "$OUT/summary.txt"
echo "rc=${PIPESTATUS[0]}" | tee -a "$OUT/summary.txt"

p2() { # NAME NODES UPPER_CORNER
  local name=$1 prm=/tmp/$1.prm t0 t1 rc peak
  cp "$ROOT/prm/granular_collapse_3d.prm" "$prm"
  printf '%s\n' "subsection Grid" "  set Upper corner = $3" "  set Nodes = $2" "end" \
    "subsection Output" "  set Directory = /tmp/$name" "  set Progress interval = 0" "end" \
    "subsection Backend" "  set Backend = cuda" "end" >>"$prm"
  nvidia-smi --query-gpu=memory.used --format=csv,noheader,nounits -lms 100 >"/tmp/$name.mem" &
  local sampler=$!
  t0=$(date +%s.%N)
  timeout 200 "$BIN/dealii-mpm" "$prm" >"$OUT/$name.log" 2>&1
  rc=$?
  t1=$(date +%s.%N)
  kill $sampler 2>/dev/null; wait $sampler 2>/dev/null
  peak=$(sort -n "/tmp/$name.mem" | tail -1)
  printf '%-16s rc=%d wall %.2f s  device memory %d MiB over idle | %s | %s\n' "$name" $rc \
    "$(awk "BEGIN{print $t1 - $t0}")" $((peak - idle)) "$(grep -o 'nodes near the material: [0-9]* at the end.*' "$OUT/$name.log")" \
    "$(grep -E 'done, t =' "$OUT/$name.log" | sed 's/^dealii-mpm: //')" | tee -a "$OUT/summary.txt"
  grep -E "loop on rank|set-up|output:" "$OUT/$name.log" | sed "s/^/  $name: /" | tee -a "$OUT/summary.txt"
}
for round in $(seq ${ROUNDS:-2}); do
  p2 p2_all all "0.6, 0.05, 0.12"
  p2 p2_near "near material" "0.6, 0.05, 0.12"
  p2 box_near "near material" "2.4, 0.1, 0.12"
  [ $round = 1 ] && [ -z "${SKIP_BOX_ALL:-}" ] && p2 box_all all "2.4, 0.1, 0.12"
done
cat "$OUT/summary.txt"
