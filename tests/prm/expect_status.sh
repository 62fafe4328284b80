#!/bin/bash
# Runs a command that must fail cleanly: exit status 1 to 127 (no signal, no hang), its output
# holding every TEXT and none of the !TEXTs, and no deal.II TimerOutput banner before the error.
# Usage: expect_status.sh TEXT... [!TEXT...] -- COMMAND [ARGUMENTS]
set -u
texts=()
while [ $# -gt 0 ] && [ "$1" != "--" ]; do texts+=("$1"); shift; done
shift
cd "$(mktemp -d)"
output=$(timeout -k 10 120 "$@" 2>&1); status=$?
echo "$output"
echo "exit status: $status"
if [ $status -eq 0 ]; then echo "FAILED: expected a non-zero exit"; exit 1; fi
if [ $status -ge 124 ]; then echo "FAILED: crashed, hung or was killed (status $status)"; exit 1; fi
if grep -qF "TimerOutput objects finalize" <<< "$output"; then echo "FAILED: deal.II's TimerOutput banner"; exit 1; fi
for text in "${texts[@]}"; do
  if [ "${text:0:1}" = "!" ]; then
    if grep -qF -- "${text:1}" <<< "$output"; then echo "FAILED: the output holds '${text:1}'"; exit 1; fi
  elif ! grep -qF -- "$text" <<< "$output"; then
    echo "FAILED: the output does not hold '$text'"; exit 1
  fi
done
echo "ok: clean exit $status"
