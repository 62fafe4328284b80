#!/bin/bash
# GPU test programs built on the development VM, run on the GPU machine: each DIR/NAME.xz (or NAME)
# is unpacked and run; then compute-sanitizer's memcheck and racecheck on those named in SANITIZE
# (default: test_gpu_transfer_conservation). The device's own build of the tests does not fit its
# calls (doc/log.md, 2026-12-05). TESTS: the names to run, in order (default every test_gpu_* of DIR);
# TEST_LIMIT: seconds per test (default 300), SANITIZE_LIMIT per sanitizer run (default 240).
#   gpu_tests_carried.sh DIR OUTDIR
set -u -o pipefail
dir=$(readlink -f "$1") out=$2
mkdir -p "$out"
# Programs that link TBB through the core (test_gpu_affine_hencky) find it only in the deal.II runtime
# (../shared/device-dealii); the GPU host has none of its own.
[ -f /opt/dl/dl-env.sh ] && . /opt/dl/dl-env.sh
. "$(dirname "$0")/gpu_unpack_build.sh"
unxz_beside "$dir"
chmod +x "$dir"/test_gpu_*
{ nvidia-smi --query-gpu=name,driver_version --format=csv,noheader; date -u; } | tee "$out/machine.txt"
status=0
if [ -n "${TESTS:-}" ]; then
  programs=()
  for n in $TESTS; do programs+=("$dir/$n"); done
else
  programs=("$dir"/test_gpu_*)
fi
for t in "${programs[@]}"; do
  case $t in *.xz) continue ;; esac
  name=$(basename "$t")
  start=$(date +%s)
  timeout "${TEST_LIMIT:-300}" "$t" >"$out/$name.log" 2>&1
  rc=$?
  [ $rc = 0 ] || status=1
  echo "== $name: rc $rc ($(($(date +%s) - start)) s)"
  tail -n 4 "$out/$name.log"
done
CS=$(ls -d /usr/local/cuda*/bin 2>/dev/null | head -1)/compute-sanitizer
for name in ${SANITIZE:-test_gpu_transfer_conservation}; do
  [ -x "$CS" ] && [ -x "$dir/$name" ] || continue
  for tool in memcheck racecheck; do
    timeout "${SANITIZE_LIMIT:-240}" "$CS" --tool $tool "$dir/$name" >"$out/$name.$tool.log" 2>&1 || status=1
    echo "== $name under $tool: $(grep -E 'ERROR SUMMARY|RACECHECK SUMMARY' "$out/$name.$tool.log" | tr '\n' ' ')"
  done
done
exit $status
