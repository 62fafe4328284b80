#!/bin/bash
# The gpu-labelled prm tests of a CUDA build of dealii-mpm (tests/prm/CMakeLists.txt, "Backend = cuda"),
# in one device call, without ctest: mpi_cuda.sh (np 1, 2, 4; cuda against cpu), kill and resume
# (1 -> 1 and 2 -> 1 ranks, double and float), SIGTERM and resume on one rank, and Grid/Nodes =
# near material on the GPU; then P2 once for its wall time. On the GPU host, from the repository root:
#   . /opt/dl/dl-env.sh && BIN=DIR bash scripts/dev/gpu_prm_checks.sh OUTDIR
# (DIR holds dealii-mpm and libdealii-mpm.so* or its .xz, scripts/dev/gpu_unpack_build.sh). P2=0 skips P2,
# CHECKPOINTS=0 the kill-and-resume cases and the earlier-run files (for a short device budget).
# A CUDA build's library (39 MB, 28 MB in xz) and libdeal.ii (28 MB in xz; ../shared/device-dealii's pack.sh
# without arguments leaves it out) do not fit one transfer with the runtime's second part, so three calls, each
# within 30 s of the last: (1) the runtime's p1 and bin, `dev_stash.sh`; (2) p2, bin and libdeal.ii.so.9.4.1.xz,
# `dev_stash.sh --require` and the library unpacked into /opt/dl/lib; (3) the build folder and this script.
# Run so on 2026-12-03 (H200): about 220 s for everything.
set -u -o pipefail
out=$1
here=$(cd "$(dirname "$0")" && pwd)
tests=$here/../../tests/prm
. "$here/gpu_unpack_build.sh"
prepare_mpi_runs "${BIN:-build-cuda/dev}" "$out"
failed=0
check mpi_cuda 360 bash "$tests/mpi_cuda.sh" "$exe" "$here/../.." /tmp/mpi_cuda
if [ "${CHECKPOINTS:-1}" != 0 ]; then
  for case in "1 1 double" "2 1 double" "1 1 float" "2 1 float"; do
    set -- $case
    check "checkpoint_KILL_np$1_np$2_$3" 150 bash "$tests/checkpoint_kill.sh" "$exe" "/tmp/ck-$1-$2-$3" "$1" "$2" KILL cuda all "$3"
  done
  check checkpoint_TERM_np1 150 bash "$tests/checkpoint_kill.sh" "$exe" /tmp/ck-term 1 1 TERM cuda
fi
check nodes_near_material_cuda 200 bash "$tests/nodes_near_material_cuda.sh" "$exe" /tmp/near-cuda
[ "${CHECKPOINTS:-1}" != 0 ] &&
  check earlier_run_files 60 bash "$tests/earlier_run_files.sh" "$exe" "$tests/collapse_small_2d.prm" /tmp/earlier
if [ "${P2:-1}" != 0 ]; then
  sed -e "s|^\( *set Directory *=\).*|\1 /tmp/p2|" "$here/../../prm/granular_collapse_3d.prm" >/tmp/p2.prm
  printf '\nsubsection Backend\n  set Backend = cuda\nend\n' >>/tmp/p2.prm
  start=$(date +%s.%N)
  timeout 120 "$exe" /tmp/p2.prm >"$out/p2.log" 2>&1
  echo "== P2: rc $?, shell clock $(awk "BEGIN{print $(date +%s.%N) - $start}") s"
  grep -E "done, t =|of steps and output|engine step" "$out/p2.log" | cut -c1-300
fi
echo "== all: $([ $failed = 0 ] && echo passed || echo FAILED)"
exit $failed
