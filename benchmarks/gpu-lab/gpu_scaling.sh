#!/bin/bash
# Backend = cuda on several MPI ranks, one GPU each: strong and weak scaling of P1 (the
# ep2-3De slump form, prm/slump_3d_ep23de.prm with the width L_y set and the random fields
# left out: set-up cost only) and P2 (prm/granular_collapse_3d.prm, 1 s, output every 0.1 s)
# end to end on 1 and 2 ranks. On the GPU host after `. /opt/dl/dl-env.sh`; prints the
# tables of scripts/dev/mpi_scaling.py (step-loop wall time, re-sorts, ghost-exchange volume).
#   gpu_scaling.sh EXE OUTDIR [STEPS] [NPS]      e.g. gpu_scaling.sh build-cuda/dealii-mpm out 300 1,2
# P1 sizes: L_y = 16.0396 m per 100,240 points (20 cells of 0.80198 m); 2053.0688 m (2560 cells)
# is the 12,830,720-point size.
set -u -o pipefail
exe=$(readlink -f "$1") out=$2 steps=${3:-300} nps=${4:-1,2}
here=$(cd "$(dirname "$0")" && pwd)
mkdir -p "$out"
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
py=$(command -v /usr/bin/python3 || command -v python3)

# p1_prm LY FILE: the slump at width LY, no random field
p1_prm() {
  "$py" - "$here/../../prm/slump_3d_ep23de.prm" "$1" "$2" <<'PY'
import re, sys
text = open(sys.argv[1]).read().replace("1.60396", sys.argv[2])
text = re.sub(r"\n *subsection Random field\n(?:.*\n)*? *end\n", "\n", text)
open(sys.argv[3], "w").write(text)
PY
}

# P2 end to end, shell clock, 1 and 2 ranks (SKIP_P2=1: not)
for np in $([ "${SKIP_P2:-0}" = 1 ] || echo 1 2); do
  d=$out/p2_np$np
  mkdir -p "$d"
  { cat "$here/../../prm/granular_collapse_3d.prm"
    printf '\nsubsection Output\n  set Directory = %s\nend\nsubsection Backend\n  set Backend = cuda\nend\n' "$d"; } > "$d.prm"
  t0=$(date +%s.%N)
  # Open MPI binds 1-2 ranks to one core each by default: a rank's host threads (output,
  # the grid built beside the first steps) would share it with the thread that drives the GPU.
  mpirun --bind-to none -np $np "$exe" "$d.prm" > "$d.log" 2>&1
  rc=$?
  t1=$(date +%s.%N)
  echo "P2 np $np: rc $rc, $(awk "BEGIN{print $t1 - $t0}") s wall (shell clock) | $(grep -E 'done, t =' "$d.log")"
  grep -E "CUDA device of rank|ghost-node exchange|GPU ghost exchange|exchange overlap|re-sorts|repartition|set-up|loop on rank" "$d.log" | head -12
  grep -A16 "Total wallclock" "$d.log" | grep -E "MPM step|migrate|repartition|output|history|setup|Total" | head -12
done

# P1: strong scaling at each size, then weak scaling (twice the width on 2 ranks)
for ly in ${P1_WIDTHS:-513.2672 2053.0688}; do
  p1_prm "$ly" "$out/p1_$ly.prm"
  "$py" "$here/../../scripts/dev/mpi_scaling.py" "$exe" --prm "$out/p1_$ly.prm" --np "$nps" --steps "$steps" --repeat 1 \
    --backend cuda --mpirun-args "--bind-to none" 2>&1 | tee "$out/p1_strong_$ly.txt"
  double=$(awk "BEGIN{printf \"%.4f\", 2 * $ly}")
  p1_prm "$double" "$out/p1_$double.prm"
  "$py" "$here/../../scripts/dev/mpi_scaling.py" "$exe" --prm "$out/p1_$double.prm" --np 2 --steps "$steps" --repeat 1 \
    --backend cuda --mpirun-args "--bind-to none" 2>&1 | tee "$out/p1_weak_$double.txt"
done
