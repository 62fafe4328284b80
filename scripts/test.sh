#!/bin/bash
# Fresh Debian 12, as root: install, build, run the tests (GPU tests skip without a GPU).
#   bash scripts/test.sh          the suite CI runs: every test but those labelled long
#   bash scripts/test.sh --quick  after a change, a few minutes: the core, the deal.II layer, the FEM
#                                 stage, the layers' directions and the smoke runs of the shipped scenes
#   bash scripts/test.sh --full   every test, then the sanitizer build and its tests (scripts/dev/sanitize.sh)
# The tiers and what each leaves out: doc/guards.md, "Test tiers".
set -euo pipefail
cd "$(dirname "$0")/.."
tier=${1:-ci}
case "$tier" in
  ci | --quick | --full) ;;
  *)
    echo "scripts/test.sh: unknown option '$tier'; allowed: --quick, --full, or none (the CI suite)" >&2
    exit 2
    ;;
esac
bash scripts/setup.sh
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
# Open MPI probes UCX at each start (0.2 s of every mpirun here) and then takes ob1 on one machine
# anyway; naming it saves the probe, nothing else changes.
export OMPI_MCA_pml=ob1
case "$tier" in
  --quick) selection=(-L '^(core|dealii|fem|fields|structure|quick)$' -LE '^long$') ;;
  ci) selection=(-LE '^long$') ;;
  --full) selection=() ;;
esac
(cd build && ctest -j "$(nproc)" --output-on-failure --timeout 900 "${selection[@]}")
if [ "$tier" = --full ]; then
  # Our code again with AddressSanitizer + UndefinedBehaviorSanitizer in build-asan (only the core
  # tests and the executable), and the core tests and short prm scenes there (doc/guards.md).
  bash scripts/dev/sanitize.sh
fi
