#!/bin/bash
# V7 end to end at reduced size (FEM cells of 2 m, MPM cells of 1 m: the same ratio of points
# to MPM cells as the scene's; 4 s of MPM): prm/slope_strength_reduction_2d.prm twice through
# dealii-mpm,
#   failing: strength reduction, then the MPM with the strengths divided by 2 (the MPM at this
#            resolution holds beyond the FEM's F: doc/prefailure.md);
#   stable:  gravity loading only, then the MPM with the prm's strengths (F = 1);
# and check_end_to_end.py asserts what each must show. Usage: end_to_end.sh EXE SOURCE_DIR OUT
set -eu
exe=$1 src=$2 out=$3 here=$(dirname "$0")
scene=$src/prm/slope_strength_reduction_2d.prm
mkdir -p "$out"
common=("subsection Grid" "  set Cell size = 1" "end" "subsection Solver" "  set End time = 4" "end"
        "subsection Output" "  set Output interval = 0" "  set History every n steps = 20" "end")
bash "$here/../run_scene.sh" "$exe" "$scene" "$out/failing" 1 "${common[@]}" \
  "subsection Pre-failure analysis" "  set Cell size = 2" "  set MPM strength factor = 2" "end" > "$out/failing.log" 2>&1 \
  || { cat "$out/failing.log"; exit 1; }
bash "$here/../run_scene.sh" "$exe" "$scene" "$out/stable" 1 "${common[@]}" \
  "subsection Pre-failure analysis" "  set Cell size = 2" "  set Method = gravity loading" "  set MPM strength factor = 1" "end" \
  > "$out/stable.log" 2>&1 || { cat "$out/stable.log"; exit 1; }
/usr/bin/python3 "$here/check_end_to_end.py" "$out"
