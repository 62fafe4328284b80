#!/bin/bash
# Resumed from each checkpoint: the reduced V3 collapse (collapse_small_2d.prm, 0.3 s, about
# 2,600 steps) runs on NP ranks keeping a checkpoint every 100 steps; the run is then resumed
# from several of them, each into a folder of its own, on the same ranks, and every resumed
# run's final particle tables and time steps must be those of the run left alone, to the bit.
#   checkpoint_resume_each.sh EXE OUTDIR NP [PRECISION] [STEPS]
# STEPS (default "300 400 500 800 1200 1600"): the checkpoints resumed from. Unlike
# checkpoint_kill.sh, which resumes from one checkpoint chosen at random, this reaches the
# early ones (300-500), where the partition a resumed run's grid is built with still differs
# from the partition the run that wrote it had reached (doc/checkpoints.md).
set -eu
exe=$1 out=$2 np=$3 precision=${4:-double} steps=${5:-300 400 500 800 1200 1600}
here=$(cd "$(dirname "$0")" && pwd)
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
rm -rf "$out" && mkdir -p "$out"
prm=$out/resume_each_$np.prm
sed -e "s/set End time *= .*/set End time = 0.3/" \
    -e 's|set Directory *= output-collapse-small-2d|set Directory = OUT\n  set Write particle table = true|' \
    "$here/collapse_small_2d.prm" > "$prm"
printf '%s\n' "subsection Checkpoint" "  set Step interval = 100" "  set Number kept = 100" "end" \
  "subsection Parallel" "  set Load balance threshold = 1.02" "end" \
  "subsection Backend" "  set Precision = $precision" "end" >> "$prm"
launch() { # NP ARGS...: the executable on NP ranks
  local n=$1; shift
  if [ "$n" -gt 1 ]; then mpirun --oversubscribe -np "$n" "$exe" "$@"; else "$exe" "$@"; fi
}

sed "s|= OUT|= $out/whole|" "$prm" > "$out/whole.prm"
launch "$np" "$out/whole.prm" > "$out/whole.log" 2>&1 || { echo "FAILED: the run failed"; tail -20 "$out/whole.log"; exit 1; }
final=$(ls "$out/whole" | sed -n 's/^particle_table_\([0-9]*\)\..*/\1/p' | sort -n | tail -1)
failed=0
for step in $steps; do
  checkpoint=$(printf '%s/whole/checkpoints/checkpoint-%09d' "$out" "$step")
  [ -d "$checkpoint" ] || { echo "FAILED: no checkpoint $checkpoint"; exit 1; }
  sed "s|= OUT|= $out/from-$step|" "$prm" > "$out/from-$step.prm"
  launch "$np" "$out/from-$step.prm" --resume "$checkpoint" > "$out/from-$step.log" 2>&1 ||
    { echo "FAILED: resumed from step $step: the run failed"; tail -20 "$out/from-$step.log"; exit 1; }
  same=yes
  for f in "$out/whole"/particle_table_"$final".*.csv; do
    cmp -s "$f" "$out/from-$step/$(basename "$f")" || same=no
  done
  cmp -s <(cut -d, -f1-3 "$out/whole/history.csv" | awk -F, -v s="$step" 'NR == 1 || $3 > s') \
         <(cut -d, -f1-3 "$out/from-$step/history.csv" | awk -F, -v s="$step" 'NR == 1 || $3 > s') || same=no
  if [ $same = yes ]; then
    echo "resumed from step $step: final particle tables and time steps bit-identical"
  else
    echo "FAILED: resumed from step $step: differs from the run left alone"
    /usr/bin/python3 "$here/compare_np.py" "$out/whole" "$out/from-$step" --rtol 0 2>&1 | tail -1 || true
    failed=1
  fi
done
exit $failed
