#!/bin/bash
# Bad-input test: dealii-mpm must exit non-zero (not crash) and print the text given in
# the prm file's first line "# expect: TEXT" (the offending entry's name).
# Usage: expect_error.sh EXE PRM [NP]
set -u
exe=$1 prm=$2 np=${3:-1}
expected=$(sed -n '1s/^# expect: //p' "$prm")
[ -n "$expected" ] || { echo "test error: $prm has no '# expect:' first line"; exit 2; }
cd "$(mktemp -d)"
if [ "$np" -gt 1 ]; then
  export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
  output=$(timeout -k 10 120 mpirun --oversubscribe -np "$np" "$exe" "$prm" 2>&1); status=$?
else
  output=$(timeout -k 10 120 "$exe" "$prm" 2>&1); status=$?
fi
echo "$output"
echo "exit status: $status"
if [ $status -eq 0 ]; then echo "FAILED: expected a non-zero exit"; exit 1; fi
if [ $status -ge 124 ]; then echo "FAILED: crashed, hung or was killed (status $status)"; exit 1; fi
if grep -qF "TimerOutput objects finalize" <<< "$output"; then echo "FAILED: deal.II's TimerOutput banner came before the error"; exit 1; fi
if ! grep -qF -- "$expected" <<< "$output"; then echo "FAILED: the message does not name '$expected'"; exit 1; fi
echo "ok: non-zero exit naming '$expected'"
