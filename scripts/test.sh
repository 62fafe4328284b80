#!/bin/bash
# Fresh Debian 12, as root: install, build, run the test suite (GPU tests skip without a GPU).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
# Open MPI probes UCX at each start (0.2 s of every mpirun here) and then takes ob1 on one machine
# anyway; naming it saves the probe, nothing else changes.
export OMPI_MCA_pml=ob1
(cd build && ctest -j "$(nproc)" --output-on-failure --timeout 900)
# Our code again with AddressSanitizer + UndefinedBehaviorSanitizer in build-asan (only the core
# tests and the executable), and the core tests and short prm scenes there (doc/guards.md).
bash scripts/dev/sanitize.sh
