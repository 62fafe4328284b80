#!/bin/bash
# The prm route of the FEM hand-over (Initial state/Source = FEM file), 2D and 3D: an FEM state
# saved by fem_handover_run on 2 ranks, read by the dealii-mpm executable on 1 and 2 ranks, must
# give the points the API gives the FEM program itself (fem_handover_run on 1 rank), in both
# placements, after 100 steps (compare_np.py: positions and stresses to 1e-10 of their magnitude).
# In 3D the API's own run on 2 ranks is compared too (2D: dealii/fem_handover_np12).
# Usage: fem_state_file.sh FEM_HANDOVER_RUN DEALII_MPM SOURCE_DIR WORK_DIR
set -euo pipefail
run=$1 exe=$2 src=$3 work=$4
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
rm -rf "$work" && mkdir -p "$work" && cd "$work"
compare() { /usr/bin/python3 "$src/tests/prm/compare_np.py" "$@" --rtol 1e-10; }
for dim in 2 3; do
  flag="" suffix=""
  [ $dim = 3 ] && flag="--3d" suffix="-3d"
  mpirun --oversubscribe -np 2 "$run" $flag --save "state$suffix.fem-state"
  "$run" $flag "api-a$suffix" > "api-a$suffix.log"
  "$run" $flag "api-b$suffix" lattice > "api-b$suffix.log"
  if [ $dim = 3 ]; then
    mpirun --oversubscribe -np 2 "$run" $flag "api-a$suffix-np2" > "api-a$suffix-np2.log"
    mpirun --oversubscribe -np 2 "$run" $flag "api-b$suffix-np2" lattice > "api-b$suffix-np2.log"
    compare "api-a$suffix" "api-a$suffix-np2"
    compare "api-b$suffix" "api-b$suffix-np2"
  fi
  for placement in a b; do
    prm="$src/tests/dealii/fem_state_file_$placement${suffix/-/_}.prm"
    for np in 1 2; do
      mkdir -p "file-$placement$suffix-np$np" && cd "file-$placement$suffix-np$np"
      mpirun --oversubscribe -np $np "$exe" "$prm" > run.log
      cd ..
      compare "api-$placement$suffix" "file-$placement$suffix-np$np/output"
    done
  done
done
# Bad input: a file that is not an FEM state, a material_id without an MPM material, a 3D state
# in a 2D scene. (set -e does not act on "! cmd" or on the left of "&&": each check fails the
# test explicitly.)
refused() { # refused PRM TEXT...: non-zero exit, and the message holds every TEXT
  local prm=$1; shift
  if "$exe" "$prm" > "$prm.log" 2>&1; then echo "FAILED: $prm was accepted"; exit 1; fi
  for text in "$@"; do
    grep -qF -- "$text" "$prm.log" || { cat "$prm.log"; echo "FAILED: no '$text' in the message"; exit 1; }
  done
}
echo "not a state" > broken.fem-state
sed 's|../state.fem-state|broken.fem-state|' "$src/tests/dealii/fem_state_file_a.prm" > broken.prm
refused broken.prm "Initial state/FEM file" "is not an FEM state"
sed 's|set Materials = 0: soil, 1800|set Materials = 3: soil, 1800|; s|../state.fem-state|state.fem-state|' \
  "$src/tests/dealii/fem_state_file_a.prm" > unnamed.prm
refused unnamed.prm "Initial state/Materials" "material_id 0"
sed 's|../state.fem-state|state-3d.fem-state|' "$src/tests/dealii/fem_state_file_a.prm" > other_dimension.prm
refused other_dimension.prm "Initial state/FEM file" "holds a 3D state, the scene is 2D"
echo "FEM file route: API and executable agree in both placements, 2D and 3D, on 1 and 2 ranks; bad files refused"
