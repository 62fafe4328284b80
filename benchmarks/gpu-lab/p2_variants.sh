#!/usr/bin/env bash
# On the GPU machine (deal.II runtime unpacked, `. /opt/dl/dl-env.sh`): runs the P2 scene
# (prm/granular_collapse_3d.prm, 512,000 points, 1 s) with Backend = cuda in variants that
# separate physics from hand-over effects: field writing off, but the hand-over to deal.II
# (store, re-sort, load) still happens every "Output interval". Prints wall time, steps, the
# final toe (max x) and height (max z) from history.csv.
# Usage: BIN=dir bash benchmarks/gpu-lab/p2_variants.sh [variant names]
set -u -o pipefail
ROOT=$(cd "$(dirname "$0")/../.." && pwd)
BIN=$(cd "${BIN:-$ROOT/build-cuda/dev}" && pwd)
# dealii-mpm links libdealii-mpm.so: copied beside it into $BIN (cp -P build-cuda/libdealii-mpm.so* $BIN).
export LD_LIBRARY_PATH="$BIN${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}"
WORK=${WORK:-/tmp/p2-variants}
mkdir -p "$WORK"
export OMPI_MCA_ess_singleton_isolated=1
DL=${DL:-/opt/dl}
if [ -f "$BIN/libdeal.ii.so.9.4.1.xz" ] && [ ! -e "$DL/lib/libdeal.ii.so.9.4.1" ]; then
  python3 -c "import lzma,shutil,sys; shutil.copyfileobj(lzma.open(sys.argv[1]), open(sys.argv[2],'wb'))" \
    "$BIN/libdeal.ii.so.9.4.1.xz" "$DL/lib/libdeal.ii.so.9.4.1"
fi
variant() { # NAME OUTPUT_INTERVAL FLIP_FRACTION PRESSURE_AVERAGING
  local name=$1 prm=$WORK/$1.prm t0 t1 rc
  cp "$ROOT/prm/granular_collapse_3d.prm" "$prm"
  cat >>"$prm" <<PRM
subsection Solver
  set FLIP fraction = $3
  set Pressure averaging = $4
end
subsection Output
  set Directory = $WORK/$name
  set Output interval = $2
  set Write particles = false
  set Write grid fields = false
  set Progress interval = 0
end
subsection Backend
  set Backend = cuda
end
PRM
  t0=$(date +%s.%N)
  (cd "$WORK" && timeout 170 "$BIN/dealii-mpm" "$prm") >"$WORK/$name.log" 2>&1
  rc=$?
  t1=$(date +%s.%N)
  printf '%-28s rc=%d wall %6.1f s | %s\n' "$name" $rc "$(awk "BEGIN{print $t1 - $t0}")" \
    "$(python3 - "$WORK/$name/history.csv" <<'PY'
import csv, sys
rows = list(csv.DictReader(open(sys.argv[1])))
r = rows[-1]
print(f"t {float(r['time']):.3f} s, step {r['step']}, dt {float(r['dt']):.2e}, toe {float(r['max_x']):.4f} m, "
      f"height {float(r['max_z']):.4f} m, removed {r['n_removed']}")
PY
)"
  [ $rc = 0 ] || grep -E "error|unstable" "$WORK/$name.log" | head -3
  grep -E "MPM step|output|migrate" "$WORK/$name.log" | head -3
}
# Names given on the command line run only those variants.
for name in ${@:-flip1_noavg_handover0.1 flip0.99_avg_handover0.1 flip0.99_avg_nohandover}; do
  case $name in
    flip1_noavg_handover0.1) variant "$name" 0.1 1 false ;;
    flip0.99_avg_handover0.1) variant "$name" 0.1 0.99 true ;;
    flip0.99_avg_nohandover) variant "$name" 0 0.99 true ;;
    *) echo "unknown variant $name" ;;
  esac
done
