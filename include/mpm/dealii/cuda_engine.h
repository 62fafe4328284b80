// Backend = cuda: the Engine<dim> (engine.h) over mpm::cuda::DeviceEngine, whose
// points and nodes stay in device memory for the whole run.
#pragma once

#include <mpm/dealii/engine.h>

#include <deal.II/base/mpi.h>

#include <future>

namespace mpm
{
  // Starts creating the CUDA context on a thread of its own (where this build has the
  // CUDA engine), so that it overlaps the set-up of the grid and the points; wait on the
  // result before make_cuda_engine. The device is the rank's: its rank among the ranks of
  // its node (MPI_COMM_TYPE_SHARED), modulo the node's devices. A ready future in builds
  // without CUDA. Collective over the communicator.
  std::future<void> start_cuda_initialisation(MPI_Comm communicator);

  // Whether this build has the CUDA engine (configured with -DMPM_WITH_CUDA=ON).
  bool cuda_engine_built();

  // Both throw naming Backend/Backend where this build has no CUDA engine (configured
  // without -DMPM_WITH_CUDA=ON) or where no CUDA device is found (on any rank).

  // One rank: the device keeps the lattice's nodes (lattice_grid) in lattice order, or,
  // with active_block_cells > 0, those near the points (Grid/Nodes = near material).
  // single_precision (Backend/Precision = float): the points, nodes and step in float on
  // the device.
  template <int dim>
  std::unique_ptr<Engine<dim>> make_cuda_engine(const HostGrid<dim, double> &lattice,
                                                const std::vector<MaterialParameters<double>> &materials,
                                                ShapeFunction shape, int active_block_cells = 0,
                                                bool single_precision = false);

  // Several ranks, one GPU each (ranks of a node beyond its GPUs share them): the device
  // keeps the rank's locally relevant nodes in the grid's numbering; after each P2G pass
  // the ghost and import entries are packed on the device, staged through pinned host
  // memory and summed over the ranks by the grid's Partitioner (in float where
  // single_precision: half the bytes). Collective.
  template <int dim>
  std::unique_ptr<Engine<dim>> make_cuda_engine(BackgroundGrid<dim> &grid,
                                                const std::vector<MaterialParameters<double>> &materials,
                                                ShapeFunction shape, bool single_precision = false);
} // namespace mpm
