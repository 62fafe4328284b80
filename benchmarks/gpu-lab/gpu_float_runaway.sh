#!/bin/bash
# The reduced collapse in float with Backend = cuda on 2 ranks (sharing a GPU where only one is lent), run on to
# 2 s with a checkpoint every 100 steps: the run in which points sheared along the no-slip base got a negative
# volume (det F in float) and the settled heap burst into motion (doc/methods.md, "Points sheared along a no-slip
# base"). N runs per mode, in turn:
#   overlap: as the first failing runs; no-overlap: MPM_CUDA_OVERLAP=0; pic: FLIP fraction 0.99 (some PIC against
#   pure FLIP's noise at rest); no-checkpoint: Step interval 0.
# Prints, per run, whether it reached 2 s, its smallest time step, and the largest ratio of kinetic energy to the
# work of gravity from 0.9 s on (settled: about 0.005; a burst: above 1), and for a run that did not reach 2 s or
# burst, where (benchmarks/gpu-lab/float_runaway_where.py: the fastest point, its rank, the ranks' x-ranges, from the
# particle tables written at each output). The runs go to WORK (default /tmp/float-runaway: their outputs are too
# many files to come back); OUTDIR/runs.tar.gz keeps their logs and histories.
# On the GPU host, from the repository root:
#   . /opt/dl/dl-env.sh && BIN=build-cuda/dev [N=4] [MODES='overlap no-overlap'] bash benchmarks/gpu-lab/gpu_float_runaway.sh OUTDIR
set -u -o pipefail
out=$1
here=$(cd "$(dirname "$0")" && pwd)
. "$here/../../scripts/dev/gpu_unpack_build.sh"
prepare_mpi_runs "${BIN:-build-cuda/dev}" "$out"
out=$(readlink -f "$out") work=${WORK:-/tmp/float-runaway}
mkdir -p "$work"
# The checkpoint test's scene (tests/prm/checkpoint_kill.sh with Backend = cuda, float, 2 ranks).
scene() { # DIR CHECKPOINT_INTERVAL FLIP
  sed -e "s/set End time *= .*/set End time = 2/" -e "s/set FLIP fraction *= .*/set FLIP fraction = $3/" \
      -e "s|set Directory *= output-collapse-small-2d|set Directory = $1|" "$here/../../tests/prm/collapse_small_2d.prm"
  printf '%s\n' "subsection Checkpoint" "  set Step interval = $2" "  set Number kept = 3" "end" \
    "subsection Parallel" "  set Load balance threshold = 1.02" "end" \
    "subsection Backend" "  set Backend = cuda" "  set Precision = float" "end" \
    "subsection Output" "  set History every n steps = 10" "  set Write particle table = true" "end"
}
for k in $(seq 1 "${N:-4}"); do
  for mode in ${MODES:-overlap no-overlap pic no-checkpoint}; do
    interval=100 flip=1 overlap=1
    case $mode in
      no-overlap) overlap=0 ;;
      pic) flip=0.99 ;;
      no-checkpoint) interval=0 ;;
      overlap) ;;
      *) echo "unknown mode $mode (overlap, no-overlap, pic, no-checkpoint)"; exit 2 ;;
    esac
    run=$work/$mode-$k
    scene "$run" "$interval" "$flip" > "$run.prm"
    start=$(date +%s)
    MPM_CUDA_OVERLAP=$overlap timeout "${LIMIT:-40}" mpirun --oversubscribe -x MPM_CUDA_OVERLAP -np 2 "$exe" "$run.prm" \
      > "$run.log" 2>&1
    rc=$?
    smallest=$(awk -F, 'NR > 1 && $2 > 0 { if (min == "" || $2 < min) min = $2 } END { print min }' "$run/history.csv")
    reached=$(tail -1 "$run/history.csv" | cut -d, -f1)
    settled=$(awk -F, 'NR > 1 && $1 >= 0.9 && $5 > 0 { r = $4 / $5; if (r > m) m = r } END { printf "%.3g", m }' \
      "$run/history.csv")
    echo "$mode $k: rc $rc, $(($(date +%s) - start)) s, reached t = $reached, smallest dt $smallest," \
      "kinetic energy / work of gravity from 0.9 s at most $settled"
    awk -v t="$reached" -v r="$settled" 'BEGIN { exit !(t < 1.999 || r > 0.02) }' &&
      python3 "$here/float_runaway_where.py" "$run" 0.05
  done
done
(cd "$work" && tar czf "$out/runs.tar.gz" ./*.log ./*.prm ./*/history.csv)
