#!/bin/bash
# Where the time of Backend = cuda on several ranks goes: P1 (the ep2-3De slump form without
# random fields, benchmarks/gpu-lab/gpu_scaling.sh's scene) for STEPS steps on 1 rank, on 2 ranks with a
# GPU each, and on 2 ranks sharing GPU 0 (CUDA_VISIBLE_DEVICES=0). Each run prints the CUDA
# per-launch times of 5 steps on every rank (MPM_CUDA_KERNEL_TIMES), the TimerOutput rows and
# the largest memory and utilisation nvidia-smi saw on each GPU. On the GPU host after
# `. /opt/dl/dl-env.sh`:   gpu_rank_check.sh EXE OUTDIR [WIDTH_M] [STEPS]   (ONE_GPU=0: without the shared run,
# NP1=0: without the one-rank run, END_TIME: the scene's End time, 15 s, the steps' limit)
# WIDTH_M 513.2672 is P1 at 3,207,680 points, 2053.0688 at 12,830,720.
set -u -o pipefail
exe=$(readlink -f "$1") out=$2 width=${3:-513.2672} steps=${4:-100}
here=$(cd "$(dirname "$0")" && pwd)
mkdir -p "$out"
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
py=/usr/bin/python3; "$py" -c "import re" 2>/dev/null || py=python3
"$py" - "$here/../../prm/slump_3d_ep23de.prm" "$width" "$out/p1.prm" "$steps" "$out/o" "${END_TIME:-15}" <<'PY'
import re, sys
text = open(sys.argv[1]).read().replace("1.60396", sys.argv[2])
text = re.sub(r"\n *subsection Random field\n(?:.*\n)*? *end\n", "\n", text)
text += (f"\nsubsection Solver\n  set Maximum number of steps = {sys.argv[4]}\n  set End time = {sys.argv[6]}\nend\n"
         f"subsection Output\n  set Directory = {sys.argv[5]}\n  set Output interval = 0\n"
         "  set Write particles = false\n  set Write grid fields = false\n  set Progress interval = 0\nend\n"
         "subsection Backend\n  set Backend = cuda\nend\n")
open(sys.argv[3], "w").write(text)
PY
# run NAME NP [mpirun options]
run() {
  local name=$1 np=$2
  shift 2
  nvidia-smi --query-gpu=index,utilization.gpu,memory.used --format=csv,noheader,nounits -lms 200 \
    >"$out/$name.smi" 2>/dev/null &
  local smi=$!
  MPM_CUDA_KERNEL_TIMES=${KERNEL_TIMES_FROM:-20} mpirun --bind-to none -np "$np" "$@" "$exe" "$out/p1.prm" \
    >"$out/$name.log" 2>&1
  local rc=$?
  kill $smi 2>/dev/null
  wait $smi 2>/dev/null
  echo "== $name (np $np, rc $rc)"
  grep -E "done, t =|of steps and output|CUDA device of rank|per-launch|GPU ghost exchange|exchange overlap|loop on rank" "$out/$name.log" | cut -c1-400
  grep -E "\| (MPM step|migrate points|repartition) |built on a thread" "$out/$name.log"
  awk -F', ' '{ if ($3 > mem[$1]) mem[$1] = $3; if ($2 > util[$1]) util[$1] = $2 }
              END { for (g in mem) printf "  GPU %s: at most %s MiB, %s%% busy\n", g, mem[g], util[g] }' "$out/$name.smi"
}
[ "${NP1:-1}" = 1 ] && run np1 1
run np2 2
[ "${ONE_GPU:-1}" = 1 ] && run np2_one_gpu 2 -x CUDA_VISIBLE_DEVICES=0
