#!/bin/bash
# GPU test programs built on the development VM, run on the GPU machine: each DIR/NAME.xz (or NAME)
# is unpacked and run; then compute-sanitizer's tools (SANITIZE_TOOLS, default "memcheck racecheck")
# on those named in SANITIZE (default: test_gpu_transfer_conservation), each NAME or NAME:ARGUMENT
# (test_gpu_transfer_conservation:--short, the form racecheck finishes). The device's own build of
# the tests does not fit its calls (doc/log.md, 2026-12-05). TESTS: the names to run, in order
# (default every test_gpu_* of DIR); TEST_LIMIT: seconds per test (default 300), SANITIZE_LIMIT per
# sanitizer run (default 240).
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
for entry in ${SANITIZE:-test_gpu_transfer_conservation}; do
  name=${entry%%:*} args=()
  [ "$entry" = "$name" ] || args=("${entry#*:}")
  [ -x "$CS" ] && [ -x "$dir/$name" ] || continue
  for tool in ${SANITIZE_TOOLS:-memcheck racecheck}; do
    log="$out/$name.$tool.log"
    start=$(date +%s)
    # Line-buffered output: a run cut by the limit still shows how far it came.
    timeout "${SANITIZE_LIMIT:-240}" stdbuf -oL "$CS" --tool $tool "$dir/$name" "${args[@]}" >"$log" 2>&1 || status=1
    echo "== $name ${args[*]} under $tool ($(($(date +%s) - start)) s): $(grep -E 'ERROR SUMMARY|RACECHECK SUMMARY|all checks passed' "$log" | tr '\n' ' ')"
  done
done
exit $status
