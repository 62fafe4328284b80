// A dealii-mpm run: set up the grid and the points, then step until the end time,
// writing output and the time history. Reads top to bottom as the algorithm.
#pragma once

#include <mpm/dealii/parameters.h>

#include <mpi.h>

namespace mpm
{
  template <int dim>
  class Simulator
  {
  public:
    Simulator(const Parameters &parameters, MPI_Comm communicator);
    void run();

  private:
    const Parameters parameters;
    MPI_Comm         communicator;
  };

  // Runs the simulator of the parameter file's dimension.
  void run_simulation(const Parameters &parameters, MPI_Comm communicator);
} // namespace mpm
