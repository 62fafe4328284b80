#!/usr/bin/env bash
# On the GPU machine (deal.II runtime unpacked, `. /opt/dl/dl-env.sh`): the method study's scenes through
# dealii-mpm with Backend = cuda (scripts/validation/study.py --backend cuda), for the methods the device runs.
#   BIN=dir SCENES=v1,v2 [PRECISIONS=FP64,FP32] bash benchmarks/gpu-lab/gpu_study.sh
#   (dir: dealii-mpm, libdealii-mpm.so*.xz, libdeal.ii.so.9.4.1.xz)
# Writes $OUT/study_cuda_<scenes>[_<precisions>].csv and the log.
set -u -o pipefail
ROOT=$(cd "$(dirname "$0")/../.." && pwd)
BIN=$(cd "${BIN:?BIN: the folder with the CUDA build of dealii-mpm}" && pwd)
OUT=${OUT:-$ROOT/out}
SCENES=${SCENES:-v1,v2,v3}
METHODS=${METHODS:-gimp,linear,cpgimp_det_f,cpgimp_f_ii,cpgimp_u,bspline2,bspline3,gimp_pic,gimp_flip,bspline2_pic}
mkdir -p "$OUT"
. "$ROOT/scripts/dev/gpu_unpack_build.sh"
prepare_build "$BIN" "$OUT"
PRECISIONS=${PRECISIONS:-FP64}
tag=${SCENES//,/_}
[ "$PRECISIONS" = FP64 ] || tag="${tag}_${PRECISIONS//,/_}"
python3 "$ROOT/scripts/validation/study.py" --exe "$BIN/dealii-mpm" --backend cuda --out /tmp/study-cuda --scenes "$SCENES" \
  --methods "$METHODS" --precisions "$PRECISIONS" --csv "$OUT/study_cuda_$tag.csv" 2>&1 | tee "$OUT/study_cuda_$tag.log"
