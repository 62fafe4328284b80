#pragma once
// dealii-mpm scene.prm --check: what a scene will be, from the parameter file alone, without
// running it or writing anything: the grid, the points, the first time step and the steps it
// predicts, the outputs, and the memory estimate. The scene has passed every check a run makes
// before it generates its points (read_parameters, check_memory); what is found only as the
// points are generated (overlapping bodies, a clipped random field) or later is not checked.

#include <mpm/dealii/parameters.h>

#include <mpi.h>

#include <ostream>

namespace mpm
{
  // Runs check_memory on `communicator` (refusing as a run would) and prints the forecast on
  // rank 0. prefailure_stage: the points will come from a pre-failure FEM analysis.
  void print_run_forecast(std::ostream &out, const Parameters &parameters, MPI_Comm communicator,
                          bool prefailure_stage = false);
} // namespace mpm
