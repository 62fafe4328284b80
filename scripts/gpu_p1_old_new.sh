#!/bin/bash
# Two builds of p1_benchmark on the same GPU machine, run in turn (old, new, old, new, ...), for
# before/after figures of a kernel change: P1 at 12.8M points (400 steps) and at 511,224 points, about
# P2's size (2000 steps), ROUNDS times (default 2), then each once with --profile's per-launch times.
# OLD and NEW are p1_benchmark files or their .xz (built on the development VM: the device's own build
# takes minutes of device time).
#   gpu_p1_old_new.sh OLD NEW OUTDIR [extra p1_benchmark arguments]
set -u -o pipefail
out=$3
mkdir -p "$out"
unpack() { # FILE[.xz] NAME: an executable copy in /tmp, its path on stdout
  case $1 in
    *.xz) python3 -c "import lzma,shutil,sys; shutil.copyfileobj(lzma.open(sys.argv[1]), open(sys.argv[2],'wb'))" "$1" "/tmp/$2" ;;
    *) cp "$1" "/tmp/$2" ;;
  esac
  chmod +x "/tmp/$2" && echo "/tmp/$2"
}
old=$(unpack "$1" p1_old) new=$(unpack "$2" p1_new) || exit 1
shift 3
{ nvidia-smi --query-gpu=name,driver_version --format=csv,noheader; date -u; } | tee "$out/machine.txt"
row() { # BUILD ARGS...: the result row of one run
  local b=$1
  shift
  echo "== $(basename "$b") $* ($(date +%T))"
  timeout 150 "$b" "$@" 2>&1 | tee -a "$out/rows_full.log" | grep -E "^\| FP|^    " | tail -8
}
{
  for round in $(seq "${ROUNDS:-2}"); do
    for b in "$old" "$new"; do row "$b" --sizes 2560 --steps 400 "$@"; done
    for b in "$old" "$new"; do row "$b" --sizes 102 --steps 2000 "$@"; done
  done
  for b in "$old" "$new"; do row "$b" --sizes 2560 --steps 200 --profile "$@"; done
  for b in "$old" "$new"; do row "$b" --sizes 102 --steps 1000 --profile "$@"; done
} | tee "$out/rows.log"
