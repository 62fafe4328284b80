#!/bin/bash
# The CPU step sums in an order that does not depend on the number of threads (cpu_backend.h:
# the coloured scatters, the reductions' fixed tree): runs a scene with DEAL_II_NUM_THREADS = 1
# and 2 (overrides appended to each) and asserts that the full-precision particle tables of
# every output are identical. (deal.II caps the threads at the cores of each rank, so more
# threads than CI's two cores would run as two.)
# Usage: threads_bit_identical.sh EXE PRM OUTDIR [override lines...]
set -eu
exe=$1 prm=$2 out=$3
shift 3
here=$(dirname "$0")
table=("subsection Output" "  set Write particle table = true" "end")
for threads in 1 2; do
  DEAL_II_NUM_THREADS=$threads bash "$here/run_scene.sh" "$exe" "$prm" "$out/t$threads" 1 "${table[@]}" "$@" \
    > "$out-t$threads.log" 2>&1 || { cat "$out-t$threads.log"; echo "FAILED: the run on $threads threads failed"; exit 1; }
done
n=0
for f in "$out"/t1/particle_table_*.csv; do
  cmp "$f" "$out/t2/$(basename "$f")" || { echo "FAILED: $(basename "$f") on 2 threads differs from 1 thread"; exit 1; }
  n=$((n + 1))
done
[ "$n" -gt 1 ] || { echo "FAILED: $n particle tables, expected several"; exit 1; }
echo "$n particle tables identical on 1 and 2 threads"
