#!/bin/bash
# Kill and resume: the reduced V3 collapse (collapse_small_2d.prm, 0.3 s, about 2,600 steps,
# a checkpoint every 100 steps) is killed while it runs and continued with --resume; its
# final particle table must be that of the same run left alone.
#   checkpoint_kill.sh EXE OUTDIR NP_RUN NP_RESUME SIGNAL [BACKEND] [NODES] [PRECISION] [CELLS]
# NP_RESUME may be a list ("2,1"): the stopped run is copied and each copy resumed on one of the
# rank counts from the same checkpoint, so the runs before the stop are made once.
# SIGNAL KILL: killed with SIGKILL (every rank at once, as a lost node) once a random
# checkpoint (step 300-1500) is written; the resumed run continues from the newest complete
# checkpoint. Same ranks: bit-identical particle tables and time steps; other ranks: equal
# to round-off (1e-10 of each field's magnitude, compare_np.py).
# SIGNAL TERM: one rank, SIGTERM at a random step: the run must write a checkpoint after its
# current step and exit with status 75; resumed, it ends equal to round-off (the stop's
# checkpoint re-sorts the points, which the run left alone did not).
# BACKEND cuda (exit 77, skipped, without a CUDA device): the points come down from the GPU
# for the checkpoint; the GPU's sums have no fixed order, so the resumed run is compared to
# round-off (1e-10) on any ranks, at 0.3 s (the run lasts 2 s, to leave time to kill it).
# NODES (Grid/Nodes, default all): near material chooses the nodes anew from the resumed
# points, which must not change a bit.
# PRECISION (Backend/Precision, default double): float saves the points in double and rounds
# them back exactly, so a float run on the CPU too must resume bit-identical. Float GPU runs are
# not reproducible to the bit (atomic sums in varying order); with cuda and float the resumed
# run may differ at 0.3 s by as much as the scene in double differs from it in float on the
# same ranks (the bound of the float np tests, mpi_collapse_float.sh; doc/checkpoints.md).
# CELLS (Grid/Cells per deal.II cell, default 1): the resumed run builds deal.II cells of that many
# MPM cells again and inserts the saved points into them.
set -eu
exe=$1 out=$2 np_run=$3 np_resumes=$4 signal=$5 backend=${6:-cpu} nodes=${7:-all} precision=${8:-double} cells=${9:-1}
if [ "$backend" = cuda ] && ! nvidia-smi -L >/dev/null 2>&1; then echo "no CUDA device: skipped"; exit 77; fi
here=$(cd "$(dirname "$0")" && pwd)
# numpy for compare_np.py: Debian's python3 (CI), else the first on PATH (GPU hosts)
py=/usr/bin/python3; "$py" -c "import numpy" 2>/dev/null || py=python3
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
rm -rf "$out" && mkdir -p "$out"
prm=$out/kill_${np_run}_${np_resumes//,/-}_${signal}.prm   # a name no other test's processes carry
end_time=0.3; [ "$backend" = cuda ] && end_time=2 # a GPU runs the 0.3 s in well under a second
sed -e "s/set End time *= .*/set End time = $end_time/" \
    -e 's|set Directory *= output-collapse-small-2d|set Directory = OUT\n  set Write particle table = true|' \
    "$here/collapse_small_2d.prm" > "$prm"
printf '%s\n' "subsection Checkpoint" "  set Step interval = 100" "  set Number kept = 3" "end" \
  "subsection Parallel" "  set Load balance threshold = 1.02" "end" \
  "subsection Backend" "  set Backend = $backend" "  set Precision = $precision" "end" "subsection Grid" "  set Nodes = $nodes" "  set Cells per deal.II cell = $cells" "end" >> "$prm"
launch() { # NP ARGS...: the executable on NP ranks
  local np=$1; shift
  if [ "$np" -gt 1 ]; then mpirun --oversubscribe -np "$np" "$exe" "$@"; else "$exe" "$@"; fi
}

# The run left alone.
sed "s|= OUT|= $out/whole|" "$prm" > "$out/whole.prm"
launch "$np_run" "$out/whole.prm" > "$out/whole.log" 2>&1

# The run that is stopped.
sed "s|= OUT|= $out/stopped|" "$prm" > "$out/stopped.prm"
threshold=$(( 300 + RANDOM % 1201 ))
launch "$np_run" "$out/stopped.prm" > "$out/stopped.log" 2>&1 &
pid=$!
for _ in $(seq 1 600); do # up to 60 s
  if [ "$signal" = KILL ]; then
    last=$(ls "$out/stopped/checkpoints" 2>/dev/null | sed -n 's/^checkpoint-0*\([0-9]\+\)$/\1/p' | sort -n | tail -1)
  else
    last=$(tail -1 "$out/stopped/history.csv" 2>/dev/null | cut -d, -f3)
  fi
  if [ -n "$last" ] && [ "$last" -ge "$threshold" ] 2>/dev/null; then break; fi
  kill -0 $pid 2>/dev/null || break
  sleep 0.1
done
if [ "$signal" = KILL ]; then
  pkill -KILL -f -- "$out/stopped.prm" || true
  wait $pid 2>/dev/null || true
else
  pkill -TERM -f -- "$out/stopped.prm"
  status=0; wait $pid || status=$?
  [ "$status" -eq 75 ] || { echo "FAILED: SIGTERM: exit status $status, expected 75"; tail -20 "$out/stopped.log"; exit 1; }
  grep -q "stopped on request" "$out/stopped.log" || { echo "FAILED: no stop message"; exit 1; }
fi
if grep -q "dealii-mpm: done" "$out/stopped.log"; then
  echo "FAILED: the run ended before it was stopped (step threshold $threshold): the test needs a slower run"; exit 1
fi
echo "stopped with SIG$signal at step $last or later (threshold $threshold)"

# Resumed from the newest complete checkpoint, on each of the NP_RESUME rank counts: the stopped
# run's folder is copied first, so that every resumed run starts from the same checkpoint.
resume_and_compare() { # NP DIR: resume a copy of the stopped run in DIR on NP ranks, compare
  local np_resume=$1 dir=$2
  [ "$dir" = "$out/stopped" ] || cp -a "$out/stopped.copy" "$dir"
  sed "s|= OUT|= $dir|" "$prm" > "$dir.prm"
  launch "$np_resume" "$dir.prm" --resume "$dir/checkpoints" > "$dir.resumed.log" 2>&1 ||
    { echo "FAILED: the run resumed on $np_resume rank(s) failed"; tail -20 "$dir.resumed.log"; exit 1; }
  grep "resumed from" "$dir.resumed.log"
  if [ "$signal" = KILL ] && [ "$np_run" = "$np_resume" ] && [ "$backend" = cpu ]; then
    final=$(ls "$out/whole" | sed -n 's/^particle_table_\([0-9]*\)\..*/\1/p' | sort -n | tail -1)
    for f in "$out/whole"/particle_table_"$final".*.csv; do
      cmp "$f" "$dir/$(basename "$f")" || { echo "FAILED: $(basename "$f") differs from the run left alone"; exit 1; }
    done
    # Every column: the same steps, and the same sums (the threaded reductions are deterministic).
    cmp "$out/whole/history.csv" "$dir/history.csv" || { echo "FAILED: history.csv differs"; exit 1; }
    echo "ok: resumed on $np_resume rank(s): final particle tables and history bit-identical to the run left alone"
  elif [ "$backend" = cuda ] && [ "$precision" = float ]; then
    # The bound: the run left alone against the same scene in double, to 0.3 s, same ranks.
    if [ ! -d "$out/double" ]; then
      sed -e "s|= OUT|= $out/double|" -e "s/set End time = .*/set End time = 0.3/" \
          -e "s/set Precision = float/set Precision = double/" "$prm" > "$out/double.prm"
      launch "$np_run" "$out/double.prm" > "$out/double.log" 2>&1 ||
        { echo "FAILED: the double run failed"; tail -20 "$out/double.log"; exit 1; }
    fi
    grep -Eq "backend cuda in float" "$out/whole.log" || { echo "FAILED: the run left alone was not in float"; exit 1; }
    "$py" "$here/compare_np.py" "$out/whole" "$dir" --time 0.3 --spread "$out/double" \
      --spread-factor 1 --rtol 0
  elif [ "$backend" = cuda ]; then
    # At 0.3 s, over 1,000 steps after the checkpoint: the 2 s run settles the heap through
    # thousands of frictional contacts more, which amplify round-off as any two GPU runs
    # (whose atomic sums have no fixed order) differ by the end (doc/checkpoints.md).
    "$py" "$here/compare_np.py" "$out/whole" "$dir" --rtol 1e-10 --time 0.3
  else
    "$py" "$here/compare_np.py" "$out/whole" "$dir" --rtol 1e-10
  fi
}
resume_counts=$(echo "$np_resumes" | tr ',' ' ')
[ "$(echo $resume_counts | wc -w)" -gt 1 ] && cp -a "$out/stopped" "$out/stopped.copy"
first=1
for n in $resume_counts; do
  if [ $first = 1 ]; then resume_and_compare "$n" "$out/stopped"; first=0
  else resume_and_compare "$n" "$out/stopped-np$n"; fi
done
