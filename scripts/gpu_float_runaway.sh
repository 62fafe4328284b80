#!/bin/bash
# The open finding of doc/methods.md ("Not understood yet"): float with Backend = cuda on 2 ranks (sharing a
# GPU where only one is lent), the reduced collapse to 2 s with a checkpoint every 100 steps, ran away in 3 of 8
# runs with the overlapped exchange and in none of 3 without. N runs per mode, in turn:
#   overlap: as the failing runs; no-overlap: MPM_CUDA_OVERLAP=0; pic: FLIP fraction 0.99 (some PIC against
#   pure FLIP's noise at rest); no-checkpoint: Step interval 0.
# Prints, per run, whether it reached 2 s and its smallest time step (a runaway drives it below 1e-5 s).
# On the GPU host, from the repository root:
#   . /opt/dl/dl-env.sh && BIN=build-cuda/dev [N=4] [MODES='overlap no-overlap'] bash scripts/gpu_float_runaway.sh OUTDIR
set -u -o pipefail
out=$1
here=$(cd "$(dirname "$0")" && pwd)
. "$here/gpu_unpack_build.sh"
prepare_mpi_runs "${BIN:-build-cuda/dev}" "$out"
# The checkpoint test's scene (tests/prm/checkpoint_kill.sh with Backend = cuda, float, 2 ranks).
scene() { # DIR CHECKPOINT_INTERVAL FLIP
  sed -e "s/set End time *= .*/set End time = 2/" -e "s/set FLIP fraction *= .*/set FLIP fraction = $3/" \
      -e "s|set Directory *= output-collapse-small-2d|set Directory = $1|" "$here/../tests/prm/collapse_small_2d.prm"
  printf '%s\n' "subsection Checkpoint" "  set Step interval = $2" "  set Number kept = 3" "end" \
    "subsection Parallel" "  set Load balance threshold = 1.02" "end" \
    "subsection Backend" "  set Backend = cuda" "  set Precision = float" "end"
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
    run=$out/$mode-$k
    scene "$run" "$interval" "$flip" > "$run.prm"
    start=$(date +%s)
    MPM_CUDA_OVERLAP=$overlap timeout "${LIMIT:-40}" mpirun --oversubscribe -x MPM_CUDA_OVERLAP -np 2 "$exe" "$run.prm" \
      > "$run.log" 2>&1
    rc=$?
    smallest=$(awk -F, 'NR > 1 && $2 > 0 { if (min == "" || $2 < min) min = $2 } END { print min }' "$run/history.csv")
    echo "$mode $k: rc $rc, $(($(date +%s) - start)) s, reached t = $(tail -1 "$run/history.csv" | cut -d, -f1), smallest dt $smallest"
  done
done
