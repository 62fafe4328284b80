#!/bin/bash
# expect_error.sh on NP ranks, and the error reported once (not once per rank).
# Usage: expect_error_once.sh EXE PRM NP
set -u
out=$(bash "$(dirname "$0")/expect_error.sh" "$@"); status=$?
echo "$out"
[ $status -eq 0 ] || exit 1
n=$(grep -c 'dealii-mpm: error' <<< "$out")
[ "$n" -eq 1 ] || { echo "FAILED: the error was reported $n times"; exit 1; }
echo "ok: reported once"
