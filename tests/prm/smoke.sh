#!/bin/bash
# Smoke test of a prm scene with a reduced number of steps: the run must succeed and
# its history must be finite with the total mass conserved (no point leaves these scenes).
# Field output is off here (full-size 3D scenes have 512k points); other tests cover output.
set -eu
# A scene may add overrides of its own for this test in lines '# smoke: <prm line>' (e.g. a
# coarser mesh for its pre-failure analysis).
exe=$1 prm=$2 out=$3 steps=$4 here=$(dirname "$0")
mapfile -t own < <(sed -n 's/^# smoke: //p' "$prm")
bash "$here/run_scene.sh" "$exe" "$prm" "$out" 1 "${own[@]}" \
  "subsection Solver" "  set Maximum number of steps = $steps" "end" \
  "subsection Output" "  set History every n steps = 5" "  set Write particles = false" "  set Write grid fields = false" "end"
/usr/bin/python3 "$here/check_history.py" "$out" --conserved total_mass --rtol auto --finite
