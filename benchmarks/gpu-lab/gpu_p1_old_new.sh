#!/bin/bash
# Builds of p1_benchmark on the same GPU machine, run in turn (first, second, ..., first, ...), for
# before/after figures of a kernel change: P1 at 12.8M points (400 steps) and at 511,224 points, about
# P2's size (2000 steps), ROUNDS times (default 2), then each once with --profile's per-launch times.
# Each BUILD is a p1_benchmark file or its .xz (built on the development VM: the device's own build
# takes minutes of device time; two .xz files and the working tree exceed one call's 64 MiB, so earlier
# calls may leave some in /opt and this call name them there).
#   gpu_p1_old_new.sh OUTDIR BUILD... [-- extra p1_benchmark arguments]
set -u -o pipefail
out=$1
shift
mkdir -p "$out"
builds=()
while [ $# -gt 0 ] && [ "$1" != -- ]; do
  name=/tmp/p1_$(basename "$1" .xz)
  case $1 in
    *.xz) python3 -c "import lzma,shutil,sys; shutil.copyfileobj(lzma.open(sys.argv[1]), open(sys.argv[2],'wb'))" "$1" "$name" ;;
    *) cp "$1" "$name" ;;
  esac || exit 1
  chmod +x "$name"
  builds+=("$name")
  shift
done
[ $# -gt 0 ] && shift
{ nvidia-smi --query-gpu=name,driver_version --format=csv,noheader; date -u; } | tee "$out/machine.txt"
row() { # BUILD ARGS...: the result row of one run
  local b=$1
  shift
  echo "== $(basename "$b") $* ($(date +%T))"
  timeout 150 "$b" "$@" 2>&1 | tee -a "$out/rows_full.log" | grep -E "^\| FP|^    " | tail -8
}
{
  for round in $(seq "${ROUNDS:-2}"); do
    for b in "${builds[@]}"; do row "$b" --sizes 2560 --steps 400 "$@"; done
    for b in "${builds[@]}"; do row "$b" --sizes 102 --steps 2000 "$@"; done
  done
  for b in "${builds[@]}"; do row "$b" --sizes 2560 --steps 200 --profile "$@"; done
  for b in "${builds[@]}"; do row "$b" --sizes 102 --steps 1000 --profile "$@"; done
} | tee "$out/rows.log"
