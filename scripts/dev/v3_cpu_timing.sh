#!/usr/bin/env bash
# The CPU goal of issue 3: the full V3 2D run (prm/granular_collapse_2d.prm, 12,800 points, 1 s) on 2 cores with
# the CPU backend, timed as a user runs it (set-up, 21 outputs and history included). Prints the machine, the
# load before and after, wall and CPU time, the program's own summary line and its timer table.
#   scripts/dev/v3_cpu_timing.sh EXE [CPUS]     CPUS: a taskset list (default: two CPUs on different physical cores)
set -u -o pipefail
EXE=$(cd "$(dirname "$1")" && pwd)/$(basename "$1")
ROOT=$(cd "$(dirname "$0")/../.." && pwd)
WORK=${WORK:-/tmp/v3-cpu-timing}
mkdir -p "$WORK"
if [ $# -ge 2 ]; then
  CPUS=$2
else
  # first CPU of each of the first two physical cores (hyperthreads of one core would not be 2 cores)
  CPUS=$(for c in /sys/devices/system/cpu/cpu[0-9]*/topology/thread_siblings_list; do cut -d, -f1 "$c" | cut -d- -f1; done |
         sort -n | uniq | head -2 | paste -sd,)
fi
lscpu | grep -E "Model name|^CPU\(s\)|Thread\(s\) per core" | sed 's/  */ /g'
echo "CPUs used: $CPUS; load average before: $(cut -d' ' -f1-3 /proc/loadavg)"
cd "$WORK"
export DEAL_II_NUM_THREADS=2
TIMEFORMAT="wall %R s, user %U s, system %S s"
{ time taskset -c "$CPUS" "$EXE" "$ROOT/prm/granular_collapse_2d.prm" >"$WORK/run.log" 2>&1; } 2>"$WORK/time.txt"
rc=$(grep -q "done, t =" "$WORK/run.log" && echo 0 || echo 1)
echo "rc=$rc; load average after: $(cut -d' ' -f1-3 /proc/loadavg)"
cat "$WORK/time.txt"
grep -E "done, t =" "$WORK/run.log"
sed -n '/Total wallclock/,$p' "$WORK/run.log" | grep -E "\|" | head -14
exit $rc
