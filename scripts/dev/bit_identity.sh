#!/bin/bash
# Restructuring check: runs every shipped scene (prm/) and every prm test scene (tests/prm/*.prm)
# for a few steps on one CPU rank with the full-precision particle table written, into OUTDIR.
# Run it with the binary before and after a change, then compare the two folders:
#   scripts/dev/bit_identity.sh build-old/dealii-mpm /tmp/old
#   scripts/dev/bit_identity.sh build/dealii-mpm /tmp/new
#   scripts/dev/bit_identity.sh --compare /tmp/old /tmp/new
# A scene that stops with an error (a scene of the stability matrix) is compared by its exit status
# and whatever tables it wrote. STEPS (default 60) sets the number of steps.
set -u
here=$(cd "$(dirname "$0")/../.." && pwd)
if [ "${1:-}" = "--compare" ]; then
  old=$2 new=$3 differ=0 same=0
  for d in "$old"/*/; do
    name=$(basename "$d")
    if [ ! -d "$new/$name" ]; then echo "MISSING $name"; differ=$((differ + 1)); continue; fi
    ok=1
    cmp -s "$d/status" "$new/$name/status" || ok=0
    for t in "$d"/particle_table_*.csv; do
      [ -e "$t" ] || continue
      cmp -s "$t" "$new/$name/$(basename "$t")" || ok=0
    done
    [ "$(ls "$d" | grep -c particle_table)" = "$(ls "$new/$name" | grep -c particle_table)" ] || ok=0
    if [ $ok = 1 ]; then same=$((same + 1)); else echo "DIFFERS $name"; differ=$((differ + 1)); fi
  done
  echo "$same scene(s) bit-identical, $differ differ"
  [ $differ = 0 ]
  exit
fi
exe=$(realpath "$1") out=$2 steps=${STEPS:-60}
mkdir -p "$out"
for prm in "$here"/prm/*.prm "$here"/tests/prm/*.prm; do
  rel=${prm#"$here"/}
  name=$(echo "${rel%.prm}" | tr / _)
  dir="$out/$name"
  start=$(date +%s.%N)
  bash "$here/tests/prm/run_scene.sh" "$exe" "$prm" "$dir" 1 \
    "subsection Solver" "  set Maximum number of steps = $steps" "end" \
    "subsection Output" "  set Output interval = 0" "  set Write particle table = true" \
    "  set Write grid fields = false" "end" > "$dir.log" 2>&1
  echo $? > "$dir/status"
  printf '%-50s status %s  %6.1f s\n' "$name" "$(cat "$dir/status")" "$(echo "$(date +%s.%N) - $start" | bc)"
done
