#!/bin/bash
# A run into a directory that holds an earlier, longer run's files warns once, naming
# Output/Directory and the first and last such file; a run into a fresh directory does not.
# Usage: earlier_run_files.sh EXE PRM WORKDIR
set -u
exe=$1 prm=$2 work=$3
rm -rf "$work" && mkdir -p "$work/out"
scene() { # scene NAME END_TIME: the prm with its output in $work/out, to END_TIME
  cp "$prm" "$work/$1.prm"
  printf '\nsubsection Output\n  set Directory = %s\n  set Progress interval = 0\nend\nsubsection Solver\n  set End time = %s\nend\n' \
    "$work/out" "$2" >>"$work/$1.prm"
}
scene long 0.1
scene short 0
"$exe" "$work/long.prm" >"$work/long.log" 2>"$work/long.err" || { echo "FAILED: the first run"; cat "$work/long.err"; exit 1; }
if grep -q "Output/Directory" "$work/long.err"; then echo "FAILED: a fresh directory warned"; cat "$work/long.err"; exit 1; fi
ls "$work/out/particles_00002.pvtu" >/dev/null || { echo "FAILED: the first run wrote no third output"; exit 1; }
"$exe" "$work/short.prm" >"$work/short.log" 2>"$work/short.err" || { echo "FAILED: the second run"; cat "$work/short.err"; exit 1; }
cat "$work/short.err"
n=$(grep -c "Parameter 'Output/Directory'.*left by an earlier run (grid_00001.0.vtu ... particles_00002.pvtu)" "$work/short.err")
[ "$n" -eq 1 ] || { echo "FAILED: the warning naming the earlier run's files printed $n times (once expected)"; exit 1; }
grep -q "<DataSet" "$work/out/particles.pvd" && [ "$(grep -c '<DataSet' "$work/out/particles.pvd")" -eq 1 ] ||
  { echo "FAILED: particles.pvd should hold the second run's one output"; exit 1; }
echo "ok: warned once of the earlier run's files"
