#!/usr/bin/env bash
# On the GPU machine (deal.II runtime unpacked, `. /opt/dl/dl-env.sh`): P2 (prm/granular_collapse_3d.prm,
# Backend = cuda, output every 0.1 s) with two builds of dealii-mpm run in turn, ROUNDS times: wall time
# by the shell clock and the engine's ms per step. Each build's directory holds dealii-mpm and
# libdealii-mpm.so.0.2 (or .xz); libdeal.ii.so.9.4.1.xz may travel in NEW.
#   OLD=dir NEW=dir [ROUNDS=3] bash benchmarks/gpu-lab/gpu_p2_old_new.sh
set -u -o pipefail
ROOT=$(cd "$(dirname "$0")/../.." && pwd)
export OMPI_MCA_ess_singleton_isolated=1
. "$ROOT/scripts/dev/gpu_unpack_build.sh"
unpack_build "$OLD"
unpack_build "$NEW"
prm=/tmp/p2_old_new.prm
cp "$ROOT/prm/granular_collapse_3d.prm" "$prm"
printf '%s\n' "subsection Output" "  set Directory = /tmp/p2-old-new" "  set Progress interval = 0" "end" \
  "subsection Backend" "  set Backend = cuda" "end" >>"$prm"
for round in $(seq "${ROUNDS:-3}"); do
  for build in old new; do
    dir=$OLD; [ $build = new ] && dir=$NEW
    t0=$(date +%s.%N)
    LD_LIBRARY_PATH=$(cd "$dir" && pwd):${LD_LIBRARY_PATH:-} "$dir/dealii-mpm" "$prm" >/tmp/p2_$build.log 2>&1
    rc=$?
    t1=$(date +%s.%N)
    printf 'round %d %s rc=%d wall %.2f s | %s\n' "$round" $build $rc "$(awk "BEGIN{print $t1 - $t0}")" \
      "$(grep -o 'engine step [0-9.]*' /tmp/p2_$build.log)"
  done
done
