#!/bin/bash
# Runs dealii-mpm on a copy of a prm file with overrides appended (later entries win),
# writing into OUTDIR. Usage: run_scene.sh EXE PRM OUTDIR [NP] [override lines...]
# Exits with dealii-mpm's status.
set -u
exe=$1 prm=$2 out=$3 np=${4:-1}
shift 4 2>/dev/null || shift $#
rm -rf "$out" && mkdir -p "$out"
copy="$out/scene.prm"
cp "$prm" "$copy"
{
  echo
  echo "subsection Output"
  echo "  set Directory = $out"
  echo "  set Progress interval = 0"
  echo "end"
  for line in "$@"; do echo "$line"; done
} >> "$copy"
if [ "$np" -gt 1 ]; then
  export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
  exec mpirun --oversubscribe -np "$np" "$exe" "$copy"
else
  exec "$exe" "$copy"
fi
