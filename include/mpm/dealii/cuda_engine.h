// Backend = cuda: the Engine<dim> (engine.h) over mpm::cuda::DeviceEngine, whose
// points and nodes stay in device memory for the whole run.
#pragma once

#include <mpm/dealii/engine.h>

#include <future>

namespace mpm
{
  // Starts creating the CUDA context on a thread of its own (where this build has the
  // CUDA engine), so that it overlaps the set-up of the grid and the points; wait on the
  // result before make_cuda_engine. A ready future in builds without CUDA.
  std::future<void> start_cuda_initialisation();

  // Whether this build has the CUDA engine (configured with -DMPM_WITH_CUDA=ON).
  bool cuda_engine_built();

  // Throws naming Backend/Backend where this build has no CUDA engine (configured
  // without -DMPM_WITH_CUDA=ON) or where no CUDA device is found. On several ranks
  // make_engine refuses cuda before this is reached.

  // One rank: the device keeps the lattice's nodes (lattice_grid) in lattice order.
  template <int dim>
  std::unique_ptr<Engine<dim>> make_cuda_engine(const HostGrid<dim, double> &lattice,
                                                const std::vector<MaterialParameters<double>> &materials,
                                                ShapeFunction shape);
} // namespace mpm
