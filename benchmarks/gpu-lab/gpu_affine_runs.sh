#!/usr/bin/env bash
# TPIC, APIC and Hencky through dealii-mpm with Backend = cuda (issue 15), in one device call:
#   1. the reduced V3 collapse (tests/prm/collapse_small_2d.prm) with APIC on the quadratic B-spline and
#      Hencky's law on 1, 2 and 4 ranks sharing the GPU: np-invariant to 1e-10, points migrating with their
#      affine matrices (tests/prm/mpi_collapse.sh), then np 1 cuda against np 1 cpu (reported);
#   2. V3 2D (prm/granular_collapse_2d.prm, h = 2.5 mm, 1 s) with APIC on the quadratic B-spline: the deposit;
#   3. P2 (prm/granular_collapse_3d.prm) with TPIC, APIC on the B-spline and Hencky, local damping 0: the deposit
#      and the wall time (benchmarks/gpu-lab/p2_deposit_variants.sh).
# On the GPU host after `. /opt/dl/dl-env.sh`:   gpu_affine_runs.sh BIN OUTDIR   (BIN: benchmarks/gpu-lab/gpu_study.sh's)
#   PARTS="1 3": only those parts; P2="variant ...": those P2 variants (p2_deposit_variants.sh's names)
set -u -o pipefail
here=$(cd "$(dirname "$0")" && pwd)
bin=$(cd "$1" && pwd) out=$2
mkdir -p "$out"
. "$here/../../scripts/dev/gpu_unpack_build.sh"
prepare_build "$bin" "$out"
exe=$bin/dealii-mpm
py=/usr/bin/python3; "$py" -c "import numpy" 2>/dev/null || py=python3
export MPM_VERIFY_DRIFT_BOUND=1
method=("subsection Solver" "  set Shape function = quadratic B-spline" "  set Velocity transfer = APIC" "end"
        "subsection Material aluminium bars" "  set Elastic law = Hencky" "end")
cuda=("subsection Backend" "  set Backend = cuda" "end")
part() { [[ " ${PARTS:-1 2 3} " == *" $1 "* ]]; }
if part 1; then
echo "== 1. reduced V3, APIC + B-spline + Hencky, cuda, np 1 2 4"
timeout 200 bash "$here/../../tests/prm/mpi_collapse.sh" "$exe" "$here/../.." "$out/np124" "${method[@]}" "${cuda[@]}" 2>&1 |
  tee "$out/np124.log" | grep -E "np [124]:|largest|migrated|repartition|FAIL|Error"
echo "rc ${PIPESTATUS[0]}"
timeout 120 bash "$here/../../tests/prm/run_np.sh" "$exe" "$here/../../tests/prm/collapse_small_2d.prm" "$out/cpu" "1" \
  "subsection Parallel" "  set Load balance threshold = 1.02" "end" "${method[@]}" >"$out/cpu.log" 2>&1
"$py" "$here/../../tests/prm/compare_np.py" "$out/cpu/np1" "$out/np124/np1" --rtol 1e-10 2>&1 | tail -3
fi
if part 2; then
echo "== 2. V3 2D at 2.5 mm, APIC + B-spline, cuda, 1 s"
t0=$(date +%s.%N)
timeout 120 bash "$here/../../tests/prm/run_scene.sh" "$exe" "$here/../../prm/granular_collapse_2d.prm" "$out/v3" 1 \
  "subsection Solver" "  set Shape function = quadratic B-spline" "  set Velocity transfer = APIC" "end" "${cuda[@]}" \
  >"$out/v3.log" 2>&1
echo "rc $? wall $(awk "BEGIN{print $(date +%s.%N) - $t0}") s"
for b in 0.0025 0.005; do "$py" "$here/../../scripts/deposit.py" "$out/v3" --bin $b 2>&1 | tail -6; done
"$py" "$here/../../tests/prm/check_history.py" "$out/v3" --finite --conserved total_mass,n_points --at-rest 0.03 2>&1 | tail -2
fi
if part 3; then
echo "== 3. P2 variants"
timeout 240 bash "$here/p2_deposit_variants.sh" "$exe" "$out/p2" \
  ${P2:-tpic_no_damping apic_bspline2_no_damping cpgimp_u_hencky_no_damping no_damping}
fi
