#!/bin/bash
# Warning test: dealii-mpm must run the scene to its end (exit status 0) and print, once, on
# stderr the text given in the prm file's first line "# warn: TEXT" (the entry it names).
# Usage: expect_warning.sh EXE PRM [NP]
set -u
exe=$1 prm=$2 np=${3:-1}
expected=$(sed -n '1s/^# warn: //p' "$prm")
[ -n "$expected" ] || { echo "test error: $prm has no '# warn:' first line"; exit 2; }
cd "$(mktemp -d)"
if [ "$np" -gt 1 ]; then
  export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
  errors=$(timeout -k 10 120 mpirun --oversubscribe -np "$np" "$exe" "$prm" 2>&1 >/dev/null); status=$?
else
  errors=$(timeout -k 10 120 "$exe" "$prm" 2>&1 >/dev/null); status=$?
fi
echo "$errors"
echo "exit status: $status"
[ $status -eq 0 ] || { echo "FAILED: a warning must not stop the run"; exit 1; }
n=$(grep -cF -- "$expected" <<< "$errors")
[ "$n" -eq 1 ] || { echo "FAILED: '$expected' printed $n times on stderr (once expected)"; exit 1; }
echo "ok: the run went on, warning once of '$expected'"
