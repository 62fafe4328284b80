#!/bin/bash
# Checkpoint/At end, and the refusals of --resume.
# A run of the reduced V3 collapse to 0.02 s writes a checkpoint at its end; resumed with the
# End time raised to 0.04 s it must end where a run straight to 0.04 s ends (to round-off:
# the end's checkpoint re-sorts the points). Then --resume must refuse, with a message naming
# what is wrong and a non-zero exit below 128: a folder without checkpoints, a damaged
# run.state, a checkpoint of another grid (Grid/Cell size), a missing FOLDER argument. A resume
# that fails on damaged points leaves history.csv's rows for the next one.
#   checkpoint_extend.sh EXE OUTDIR
set -eu
exe=$1 out=$2
here=$(cd "$(dirname "$0")" && pwd)
rm -rf "$out" && mkdir -p "$out" && cd "$out"
scene() { # END_TIME DIRECTORY: the scene's prm on stdout
  sed -e "s/set End time *= .*/set End time = $1/" \
      -e "s|set Directory *= output-collapse-small-2d|set Directory = $2\n  set Write particle table = true|" \
      -e 's/set Output interval *= .*/set Output interval = 0.01/' "$here/collapse_small_2d.prm"
  printf '%s\n' "subsection Checkpoint" "  set At end = true" "end"
}
scene 0.04 straight > straight.prm
scene 0.02 extended > short.prm
scene 0.04 extended > long.prm
"$exe" straight.prm > straight.log
"$exe" short.prm > short.log
ls extended/checkpoints/checkpoint-* -d
# A first resume fails on a damaged points file after the output is set up: the rows of the
# run so far must survive it (history.csv is kept aside, not overwritten, by the second try).
cp -r extended/checkpoints/checkpoint-* broken && head -c 100 extended/checkpoints/checkpoint-*/points.0 > broken/points.0
! "$exe" long.prm --resume broken > broken.log 2>&1 || { echo "FAILED: a damaged points file was accepted"; exit 1; }
grep -q "the checkpoint is damaged" broken.log || { echo "FAILED: no message for the damaged points"; cat broken.log; exit 1; }
"$exe" long.prm --resume extended/checkpoints > long.log
grep "resumed from" long.log
/usr/bin/python3 "$here/compare_np.py" straight extended --rtol 1e-10
# (the short run's last row, at 0.02 s, stays as well)
missing=$(grep -vxFf <(cut -d, -f1-3 extended/history.csv) <(cut -d, -f1-3 straight/history.csv) || true)
[ -z "$missing" ] || { echo "FAILED: history.csv of the resumed run lacks rows of the straight run:"; echo "$missing"; exit 1; }
echo "ok: history.csv holds every row (time, dt, step) of the straight run"

refuse() { # EXPECTED_TEXT ARGS...: a non-zero exit below 128 and a message holding the text
  local expected=$1; shift
  local status=0 output
  output=$("$exe" "$@" 2>&1) || status=$?
  if [ $status -eq 0 ] || [ $status -ge 128 ]; then echo "FAILED: '$*' exited with $status"; echo "$output"; exit 1; fi
  grep -qF -- "$expected" <<< "$output" || { echo "FAILED: '$*' does not say '$expected':"; echo "$output"; exit 1; }
  echo "ok: '$*' refused: $(grep -F -- "$expected" <<< "$output" | head -1)"
}
mkdir -p empty
refuse "holds no complete checkpoint" long.prm --resume empty
refuse "is not a folder" long.prm --resume nowhere
first=$(ls -d extended/checkpoints/checkpoint-* | head -1)
cp -r "$first" damaged && head -c 20 "$first/run.state" > damaged/run.state
refuse "cannot be read as a dealii-mpm checkpoint" long.prm --resume damaged
sed 's/set Cell size *= .*/set Cell size = 0.01/' long.prm > coarser.prm
refuse "Grid/Cell size" coarser.prm --resume extended/checkpoints
refuse "Usage" long.prm --resume
