// A run with a pre-failure analysis (Pre-failure analysis/Method != none), as the executable
// does it: the analysis (prefailure_analysis.h), then, with Continue with MPM, the MPM from the
// FEM's committed state through the hand-over API (fem_handover.h, placement (a)) to End time.
#pragma once

#include <mpm/dealii/parameters.h>

#include <mpi.h>

namespace mpm::fem
{
  void run_prefailure_analysis(const Parameters &parameters, MPI_Comm communicator);
} // namespace mpm::fem
