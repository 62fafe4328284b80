#!/bin/bash
# dealii-mpm scene.prm --check: exits 0 without running or writing anything, and its forecast
# holds for the run: the same grid and number of points as the run reports, and a first time step
# whose predicted steps the run needs at least (the adaptive step only shrinks as the points speed
# up) and at most 1.5 times (the reduced V3 collapse reaches about 1 m/s against c_el = 20.7 m/s).
# A scene that the memory check refuses is refused by --check too, naming the entry.
# Usage: check_scene.sh EXE PRM WORKDIR
set -u
exe=$1 prm=$2 work=$3
rm -rf "$work" && mkdir -p "$work" && cd "$work" || exit 1
cp "$prm" scene.prm
printf '\nsubsection Output\n  set Directory = out\n  set Progress interval = 0\nend\n' >>scene.prm
"$exe" scene.prm --check >check.log 2>&1 || { cat check.log; echo "FAILED: --check exited non-zero"; exit 1; }
cat check.log
[ ! -e out ] || { echo "FAILED: --check created the output directory"; exit 1; }
points=$(sed -n 's/.*material points: about \([0-9]*\) .*/\1/p' check.log)
nodes=$(sed -n 's/.*cells, \([0-9]*\) nodes).*/\1/p' check.log)
steps=$(sed -n 's/.*about \([0-9]*\) steps to End time.*/\1/p' check.log)
[ -n "$points" ] && [ -n "$nodes" ] && [ -n "$steps" ] || { echo "FAILED: no forecast of points, nodes and steps"; exit 1; }
"$exe" scene.prm >run.log 2>&1 || { cat run.log; echo "FAILED: the run"; exit 1; }
line=$(grep -m1 -E "^dealii-mpm: [23]D, " run.log)
ran_points=$(sed -n 's/.* nodes, \([0-9]*\) material points.*/\1/p' <<<"$line")
ran_nodes=$(sed -n 's/.* cells, \([0-9]*\) nodes,.*/\1/p' <<<"$line")
ran_steps=$(sed -n 's/.* after \([0-9]*\) steps in.*/\1/p' run.log)
echo "forecast: $points points, $nodes nodes, $steps steps; run: $ran_points points, $ran_nodes nodes, $ran_steps steps"
[ "$points" = "$ran_points" ] || { echo "FAILED: $points points forecast, $ran_points in the run"; exit 1; }
[ "$nodes" = "$ran_nodes" ] || { echo "FAILED: $nodes nodes forecast, $ran_nodes in the run"; exit 1; }
[ "$ran_steps" -ge "$steps" ] && [ "$((2 * ran_steps))" -le "$((3 * steps))" ] ||
  { echo "FAILED: the run took $ran_steps steps, the forecast $steps (at least that and at most 1.5 times expected)"; exit 1; }
# the memory check refuses as a run would
printf 'subsection Resources\n  set Memory limit = 0.001\nend\n' >>scene.prm
if "$exe" scene.prm --check >refused.log 2>&1; then echo "FAILED: --check accepted a scene over the memory limit"; exit 1; fi
grep -q "Resources/Memory limit" refused.log || { cat refused.log; echo "FAILED: the refusal names no entry"; exit 1; }
echo "ok: --check forecast the run, and refused a scene over the memory limit"
