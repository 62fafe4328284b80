#!/bin/bash
# On the GPU machine: where P2's step (prm/granular_collapse_3d.prm on Backend = cuda, 512,000 points)
# spends its time, launch by launch, through the real dealii-mpm: per-launch CUDA events
# (MPM_CUDA_KERNEL_TIMES) in a short run, then the hardware counters of one step's launches from
# about step 300 on with Nsight Compute (ncu_step_metrics.sh, summed up by ncu_step_table.py).
# Steps are launched one kernel at a time (Queue steps = false) so that the profiler sees each.
#   . /opt/dl/dl-env.sh && BIN=DIR bash benchmarks/gpu-lab/gpu_p2_counters.sh OUTDIR
# DIR as for gpu_prm_checks.sh (dealii-mpm and its library or the library's .xz).
set -u -o pipefail
out=$1
here=$(cd "$(dirname "$0")" && pwd)
. "$here/../../scripts/dev/gpu_unpack_build.sh"
prepare_mpi_runs "${BIN:-build-cuda/dev}" "$out"
export PATH=/usr/local/cuda/bin:$PATH

# P2 for 0.05 s of its 1 s (about 840 steps), no output after the first.
prm() {
  sed -e "s|^\( *set Directory *=\).*|\1 /tmp/p2c|" -e "s|^\( *set End time *=\).*|\1 $1|" \
    "$here/../../prm/granular_collapse_3d.prm" >/tmp/p2c.prm
  printf '\nsubsection Backend\n  set Backend = cuda\n  set Queue steps = false\nend\n' >>/tmp/p2c.prm
}
prm 0.05
MPM_CUDA_KERNEL_TIMES=301 timeout 100 "$exe" /tmp/p2c.prm >"$out/p2_timed.log" 2>&1
echo "== timed run: rc $?"
grep -iE "launch|engine step|done, t =" "$out/p2_timed.log" | cut -c1-300

# Counters: skip the launches of about 300 steps (about 10 per step with the re-sorts), then 30.
. "$here/ncu_step_metrics.sh"
prm 0.03
start=$(date +%s)
timeout 400 ncu --kernel-name regex:"for_each_kernel|gather_kernel_bounded|reduce_" \
  --launch-skip "${SKIP:-3000}" --launch-count "${COUNT:-30}" --clock-control none --print-units base \
  --metrics "$NCU_STEP_METRICS" --csv "$exe" /tmp/p2c.prm >"$out/ncu.csv" 2>"$out/ncu.err"
echo "== ncu: rc $? ($(($(date +%s) - start)) s)"
tail -3 "$out/ncu.err"
python3 "$here/ncu_step_table.py" "$out/ncu.csv" "P2 (512,000 points)" | tee "$out/counters.md"
