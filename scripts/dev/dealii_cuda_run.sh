#!/usr/bin/env bash
# On the GPU machine, after the deal.II runtime is unpacked (../shared/device-dealii) and
# `. /opt/dl/dl-env.sh`: runs the real dealii-mpm with Backend = cuda on the P2 scene
# (prm/granular_collapse_3d.prm, 512,000 points, 1 s, output every 0.1 s), then a reduced
# copy of the same prm (Cell size 10 mm and 5 mm) with Backend = cpu and cuda, and the
# extra programs found in $BIN (test_gpu_*, fp_accuracy, p1_benchmark).
# Writes logs, histories and the reduced runs' last outputs to $OUT/results.tar.xz. From the repo root:
#   BIN=build-cuda/dev bash scripts/dev/dealii_cuda_run.sh
set -u -o pipefail
ROOT=$(cd "$(dirname "$0")/../.." && pwd)
FINAL=${OUT:-$ROOT/output-dealii-cuda}
BIN=${BIN:-$ROOT/build-cuda/dev}
WORK=${WORK:-/tmp/dealii-cuda-run}
# Everything is written under $WORK/results and packed into $FINAL/results.tar.xz at the
# end (few files come back from the device); the summary is also copied beside it.
OUT=$WORK/results
mkdir -p "$OUT" "$WORK" "$FINAL"
BIN=$(cd "$BIN" && pwd)
# dealii-mpm links libdealii-mpm.so: copied beside it into $BIN (cp -P build-cuda/libdealii-mpm.so* $BIN).
export LD_LIBRARY_PATH="$BIN${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}"
export OUT FINAL
export OMPI_MCA_ess_singleton_isolated=1 # singleton without orted
# libdeal.ii itself travels beside the binaries when the runtime bundle lacks it
DL=${DL:-/opt/dl}
if [ -f "$BIN/libdeal.ii.so.9.4.1.xz" ] && [ ! -e "$DL/lib/libdeal.ii.so.9.4.1" ]; then
  if command -v xz >/dev/null; then xz -dc -T0 "$BIN/libdeal.ii.so.9.4.1.xz" >"$DL/lib/libdeal.ii.so.9.4.1"
  else python3 -c "import lzma,shutil,sys; shutil.copyfileobj(lzma.open(sys.argv[1]), open(sys.argv[2],'wb'))" \
         "$BIN/libdeal.ii.so.9.4.1.xz" "$DL/lib/libdeal.ii.so.9.4.1"; fi
fi
status=0

{
  date -u +"%Y-%m-%d %H:%M UTC"
  nvidia-smi --query-gpu=name,driver_version,memory.total --format=csv,noheader
  nproc
} 2>&1 | tee "$OUT/machine.txt"
ldd "$BIN/dealii-mpm" | grep -i -E "not found|deal.ii|fftw|cuda" | tee -a "$OUT/machine.txt"

# prm variant: $1 source, $2 target, $3 backend, $4 cell size (or ""), $5 output dir, $6 output interval
make_prm() {
  sed -e "s|^\( *set Directory *=\).*|\1 $5|" -e "s|^\( *set Output interval *=\).*|\1 $6|" "$1" >"$2"
  [ -n "$4" ] && sed -i "s|^\( *set Cell size *=\).*|\1 $4|" "$2"
  printf '\nsubsection Backend\n  set Backend = %s\nend\n' "$3" >>"$2"
}

# run NAME PRM: wall time by the shell clock, log and history kept
run() {
  local name=$1 prm=$2 limit=${3:-120} t0 t1
  t0=$(date +%s.%N)
  (cd "$WORK" && timeout "$limit" "$BIN/dealii-mpm" "$prm") >"$OUT/$name.log" 2>&1
  local rc=$?
  t1=$(date +%s.%N)
  printf '%-14s rc=%d  wall %.2f s (shell clock)  | %s\n' "$name" $rc "$(awk "BEGIN{print $t1 - $t0}")" \
    "$(grep -E 'done, t =' "$OUT/$name.log" | sed 's/^dealii-mpm: //')" | tee -a "$OUT/summary.txt"
  [ $rc = 0 ] || { status=1; tail -20 "$OUT/$name.log"; }
}

P2=$ROOT/prm/granular_collapse_3d.prm
# P2_OUTPUT: output interval of the P2 run (0: only t = 0 and the end are written)
make_prm "$P2" "$WORK/p2_cuda.prm" cuda "" "$WORK/p2_cuda" "${P2_OUTPUT:-0.1}"
run p2_cuda "$WORK/p2_cuda.prm" 240
cp "$WORK/p2_cuda/history.csv" "$OUT/p2_cuda_history.csv" 2>/dev/null
grep -A12 "Total wallclock" "$OUT/p2_cuda.log"

# REDUCED_SIZES: cell sizes of the reduced copies run with both backends
for h in ${REDUCED_SIZES:-0.01 0.005}; do
  tag=h$(awk "BEGIN{printf \"%d\", $h * 1000}")mm
  for b in cuda cpu; do
    make_prm "$P2" "$WORK/${tag}_$b.prm" $b "$h" "$WORK/${tag}_$b" 0.5
    run "${tag}_$b" "$WORK/${tag}_$b.prm" 150
  done
done
# the reduced runs' histories and last particle outputs (pvd record, pvtu and its pieces)
python3 - "$WORK" <<'PY'
import glob, os, re, sys, tarfile
work = sys.argv[1]
with tarfile.open(os.path.join(os.environ["FINAL"], "reduced.tar.xz"), "w:xz") as tar:
    for d in sorted(glob.glob(os.path.join(work, "h*mm_*"))):
        if not os.path.isdir(d):
            continue
        pvd = os.path.join(d, "particles.pvd")
        last = re.findall(r'file="([^"]+)"', open(pvd).read())[-1]
        pvtu = os.path.join(d, last)
        files = [os.path.join(d, "history.csv"), pvd, pvtu]
        files += [os.path.join(d, s) for s in re.findall(r'Source="([^"]+)"', open(pvtu).read())]
        for f in files:
            tar.add(f, arcname=os.path.relpath(f, work))
PY
ls -l "$FINAL/reduced.tar.xz"

# GPU tests carried in $BIN (CPU vs GPU per point etc.; built from tests/gpu)
for t in "$BIN"/test_gpu_*; do
  [ -x "$t" ] || continue
  "$t" >"$OUT/$(basename "$t").log" 2>&1
  rc=$?
  echo "$(basename "$t"): rc=$rc" | tee -a "$OUT/summary.txt"
  [ $rc = 0 ] || status=1
done
grep -hE "GPU-CPU|max" "$OUT"/test_gpu_cpu_agreement.log 2>/dev/null | head -12

if [ -x "$BIN/fp_accuracy" ]; then
  "$BIN/fp_accuracy" 2>&1 | tee "$OUT/fp_accuracy.log" || status=1
fi
for b in p1_benchmark; do
  if [ -x "$BIN/$b" ]; then
    echo "== $b" | tee -a "$OUT/bench.log"
    "$BIN/$b" --sizes 160,2560 --steps 200 --profile 2>&1 | tee -a "$OUT/bench.log" || status=1
  fi
done
tar -cJf "$FINAL/results.tar.xz" -C "$WORK" results
cp "$OUT/summary.txt" "$FINAL/"
echo
cat "$OUT/summary.txt"
exit $status
