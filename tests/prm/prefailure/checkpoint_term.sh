#!/bin/bash
# A scene with a pre-failure analysis stopped by SIGTERM in its MPM stage and resumed:
# prm/slope_strength_reduction_2d.prm at reduced size (FEM and MPM cells of 1 m), gravity
# loading, the MPM's strengths divided by 2, 20 s of MPM (about 10,000 steps). Asserts: the FEM
# stage is not interrupted by the handler (it ran once); SIGTERM at a random MPM step gives a
# checkpoint and exit status 75; --resume continues without running the analysis again and with
# the strengths divided by 2 as before; its final particles equal those of the run left alone to
# round-off (1e-10, compare_np.py: the stop's checkpoint re-sorts the points); a prm whose MPM
# strength factor differs from the checkpoint's is refused, naming the entry.
# Usage: checkpoint_term.sh EXE SOURCE_DIR OUTDIR
set -eu
exe=$1 src=$2 out=$3 here=$(cd "$(dirname "$0")" && pwd)
py=/usr/bin/python3; "$py" -c "import numpy" 2>/dev/null || py=python3
rm -rf "$out" && mkdir -p "$out"
prm=$out/prefailure_term.prm # a name no other test's processes carry
sed -e 's/set Method *= strength reduction/set Method = gravity loading/' \
    -e 's|set Directory *= .*|set Directory = OUT\n  set Write particle table = true|' \
    -e 's/set Output interval *= .*/set Output interval = 5/' "$src/prm/slope_strength_reduction_2d.prm" > "$prm"
printf '%s\n' "subsection Grid" "  set Cell size = 1" "end" "subsection Solver" "  set End time = 20" "end" >> "$prm"

sed "s|= OUT|= $out/whole|" "$prm" > "$out/whole.prm"
"$exe" "$out/whole.prm" > "$out/whole.log" 2>&1 || { echo "FAILED: the run left alone failed"; tail -20 "$out/whole.log"; exit 1; }
steps=$(sed -n 's/^dealii-mpm: done, .* after \([0-9]*\) steps.*/\1/p' "$out/whole.log")
echo "the run left alone: $steps MPM steps"

sed "s|= OUT|= $out/stopped|" "$prm" > "$out/stopped.prm"
threshold=$(( steps / 10 + RANDOM % (steps / 2) ))
"$exe" "$out/stopped.prm" > "$out/stopped.log" 2>&1 &
pid=$!
last=
for _ in $(seq 1 600); do # up to 60 s
  last=$(tail -1 "$out/stopped/history.csv" 2>/dev/null | cut -d, -f3)
  if [ -n "$last" ] && [ "$last" -ge "$threshold" ] 2>/dev/null; then break; fi
  kill -0 $pid 2>/dev/null || break
  sleep 0.05
done
pkill -TERM -f -- "$out/stopped.prm" || true
status=0; wait $pid || status=$?
if grep -q "dealii-mpm: done" "$out/stopped.log"; then
  echo "FAILED: the run ended before it was stopped (step threshold $threshold): the test needs a slower run"; exit 1
fi
[ "$status" -eq 75 ] || { echo "FAILED: SIGTERM: exit status $status, expected 75"; tail -20 "$out/stopped.log"; exit 1; }
grep -q "stopped on request" "$out/stopped.log" || { echo "FAILED: no stop message"; exit 1; }
echo "stopped with SIGTERM at step $last or later (threshold $threshold), exit status 75"

# A prm with another MPM strength factor is refused.
sed 's/set MPM strength factor = 2/set MPM strength factor = 1.5/' "$out/stopped.prm" > "$out/other_factor.prm"
if output=$("$exe" "$out/other_factor.prm" --resume "$out/stopped/checkpoints" 2>&1); then
  echo "FAILED: resumed with another MPM strength factor"; exit 1
fi
grep -qF "Pre-failure analysis/MPM strength factor" <<< "$output" ||
  { echo "FAILED: the refusal does not name the entry:"; echo "$output"; exit 1; }

"$exe" "$out/stopped.prm" --resume "$out/stopped/checkpoints" > "$out/resumed.log" 2>&1 ||
  { echo "FAILED: the resumed run failed"; tail -20 "$out/resumed.log"; exit 1; }
grep "resumed from" "$out/resumed.log"
! grep -q "Pre-failure analysis done" "$out/resumed.log" || { echo "FAILED: the analysis ran again"; exit 1; }
grep -q "not run again.*divided by 2)" "$out/resumed.log" ||
  { echo "FAILED: the resumed MPM does not say it divides the strengths by 2"; exit 1; }
[ "$(grep -c "Pre-failure analysis done" "$out/stopped.log")" -eq 1 ] || { echo "FAILED: the analysis did not run once"; exit 1; }
"$py" "$here/../compare_np.py" "$out/whole" "$out/stopped" --rtol 1e-10
