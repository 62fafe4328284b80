#!/bin/bash
# The fused step (step.h, FusedTransfer) on the GPU machine, from binaries built elsewhere (the
# device's own build of the GPU tests does not fit one call): DIR holds p1_benchmark and
# test_gpu_fused_step, each as FILE or FILE.xz, and libtbb.so.12 if they need it.
#   gpu_fused_step.sh DIR OUTDIR
# 1. test_gpu_fused_step (fused GPU against the host's unfused step), then compute-sanitizer's
#    memcheck and racecheck on a small fused P1;
# 2. P1 rows, unfused and fused in turn (12.8M points, 400 steps; 511,224 points, about P2's
#    512,000, 2000 steps), twice, then each once with --profile's per-launch times.
set -u -o pipefail
dir=$(readlink -f "$1") out=$2
mkdir -p "$out"
. "$(dirname "$0")/../../scripts/dev/gpu_unpack_build.sh"
unxz_beside "$dir"
chmod +x "$dir"/p1_benchmark "$dir"/test_gpu_fused_step 2>/dev/null
export LD_LIBRARY_PATH=$dir${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}
CS=$(ls -d /usr/local/cuda*/bin 2>/dev/null | head -1)/compute-sanitizer
{ nvidia-smi --query-gpu=name,driver_version --format=csv,noheader; date -u; } | tee "$out/machine.txt"
status=0
timeout 300 "$dir/test_gpu_fused_step" >"$out/test.log" 2>&1 || status=1
grep -E "fused|FAILED|passed" "$out/test.log"
if [ -x "$CS" ]; then
  timeout 200 "$CS" --tool memcheck "$dir/p1_benchmark" --fused --sizes 2 --steps 20 >"$out/memcheck.log" 2>&1 || status=1
  timeout 200 "$CS" --tool racecheck "$dir/p1_benchmark" --fused --sizes 2 --steps 5 >"$out/racecheck.log" 2>&1 || status=1
  echo "memcheck: $(grep -E 'ERROR SUMMARY' "$out/memcheck.log" | tr '\n' ' ')"
  echo "racecheck: $(grep -E 'RACECHECK SUMMARY|ERROR SUMMARY' "$out/racecheck.log" | tr '\n' ' ')"
fi
row() { # the result row of one p1_benchmark run
  echo "== $* ($(date +%T))"
  timeout 150 "$dir/p1_benchmark" "$@" 2>&1 | tee -a "$out/rows_full.log" | grep -E "^\| |^    " | tail -8
}
{
  for round in 1 2; do
    row --sizes 2560 --steps 400
    row --sizes 2560 --steps 400 --fused
    row --sizes 102 --steps 2000
    row --sizes 102 --steps 2000 --fused
  done
  row --sizes 2560 --steps 200 --profile
  row --sizes 2560 --steps 200 --profile --fused
} | tee "$out/rows.log"
exit $status
