#!/usr/bin/env bash
# P2 (prm/granular_collapse_3d.prm: the 3D collapse, 512,000 points, 1 s) with Backend = cuda in
# variants that change one setting of the method each, to find what sets the deposit's toe
# (issue 15). Per variant: the wall time and steps of the run (particles written at t = 0 and
# t = 1 s only) and the deposit of scripts/deposit_3d.py (toe = 99.9th percentile of x, top-left
# height, slope; mid-plane and across the width). On the GPU host after `. /opt/dl/dl-env.sh`:
#   p2_deposit_variants.sh EXE OUTDIR [VARIANT...]     (default: every variant below)
# The summary goes to stdout and OUTDIR/summary.txt.
set -u -o pipefail
exe=$(readlink -f "$1") out=$2
shift 2
here=$(cd "$(dirname "$0")" && pwd)
mkdir -p "$out"
export OMPI_MCA_ess_singleton_isolated=1
py=/usr/bin/python3; "$py" -c "import numpy" 2>/dev/null || py=python3

# NAME: the lines appended to the Solver subsection.
declare -A solver=(
  [default]=""
  [no_damping]="set Local damping = 0"
  [cpgimp_u]="set GIMP domain update = U"
  [cpgimp_f_ii]="set GIMP domain update = F_ii"
  [cpgimp_det_f]="set GIMP domain update = det F"
  [bspline2]="set Shape function = quadratic B-spline"
  [flip_1]="set FLIP fraction = 1"
  [no_averaging]="set Pressure averaging = false"
  [cpgimp_u_no_damping]="set GIMP domain update = U
  set Local damping = 0"
  [tpic_no_damping]="set Velocity transfer = TPIC
  set Local damping = 0"
  [apic_bspline2_no_damping]="set Shape function = quadratic B-spline
  set Velocity transfer = APIC
  set Local damping = 0"
  [cpgimp_u_hencky_no_damping]="set GIMP domain update = U
  set Local damping = 0"
  [no_damping_0995]="set Local damping = 0
  set FLIP fraction = 0.995"
  [flip_change]="set FLIP at fixed nodes = velocity change"
  [flip_change_no_damping]="set FLIP at fixed nodes = velocity change
  set Local damping = 0"
  [flip_change_no_damping_0995]="set FLIP at fixed nodes = velocity change
  set Local damping = 0
  set FLIP fraction = 0.995"
  [flip_1_change]="set FLIP at fixed nodes = velocity change
  set FLIP fraction = 1"
  [disconnect]=""
  [flip_1_disconnect]="set FLIP fraction = 1"
  [flip_1_change_disconnect]="set FLIP at fixed nodes = velocity change
  set FLIP fraction = 1"
  [flip_change_no_damping_0995_disconnect]="set FLIP at fixed nodes = velocity change
  set Local damping = 0
  set FLIP fraction = 0.995"
)
declare -A material=([cpgimp_u_hencky_no_damping]="set Elastic law = Hencky"
  [disconnect]="set Disconnection volume ratio = 2"
  [flip_1_disconnect]="set Disconnection volume ratio = 2"
  [flip_1_change_disconnect]="set Disconnection volume ratio = 2"
  [flip_change_no_damping_0995_disconnect]="set Disconnection volume ratio = 2")
declare -A boundary=([free_slip_base]="set z min = free-slip")
all="default no_damping cpgimp_u cpgimp_f_ii cpgimp_det_f bspline2 flip_1 no_averaging free_slip_base cpgimp_u_no_damping"
[ $# -gt 0 ] && all="$*"
for name in $all; do # a misspelt name would run the prm as it is under that name
  [ -n "${solver[$name]+x}${boundary[$name]+x}" ] || { echo "unknown variant '$name'; known: ${!solver[*]} ${!boundary[*]}"; exit 2; }
done

for name in $all; do
  dir=$out/$name prm=$out/$name.prm
  cp "$here/../../prm/granular_collapse_3d.prm" "$prm"
  {
    echo "subsection Solver"
    echo "  ${solver[$name]:-}"
    echo "end"
    echo "subsection Boundary conditions"
    echo "  ${boundary[$name]:-}"
    echo "end"
    echo "subsection Material aluminium bars"
    echo "  ${material[$name]:-}"
    echo "end"
    echo "subsection Output"
    echo "  set Directory = $dir"
    echo "  set Output interval = 1"
    echo "  set Write grid fields = false"
    echo "  set Progress interval = 0"
    echo "end"
    echo "subsection Backend"
    echo "  set Backend = cuda"
    echo "end"
  } >>"$prm"
  t0=$(date +%s.%N)
  "$exe" "$prm" >"$out/$name.log" 2>&1
  rc=$?
  t1=$(date +%s.%N)
  wall=$("$py" -c "print(f'{$t1 - $t0:.1f}')")
  steps=$(grep -oE "after [0-9]+ steps" "$out/$name.log" | tail -1 | grep -oE "[0-9]+")
  step_s=$(grep -E "^\| MPM step " "$out/$name.log" | awk -F'|' '{gsub(/ /, "", $4); print $4}')
  if [ $rc = 0 ]; then
    deposit=$("$py" "$here/../../scripts/deposit_3d.py" "$dir" --json "$out/$name.json" 2>&1 | tr '\n' ' ' | cut -c1-400)
  else
    deposit="(run failed: $(grep -m1 -iE "error|unstable" "$out/$name.log" | cut -c1-200))"
  fi
  echo "== $name: rc $rc, wall $wall s, steps $steps, MPM step $step_s s; $deposit"
done | tee -a "$out/summary.txt"
