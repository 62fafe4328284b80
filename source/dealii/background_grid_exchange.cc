// The grid's sums over ranks: nodes and cells through deal.II's Partitioner (BackgroundGrid,
// background_grid.h).
#include <mpm/dealii/background_grid.h>

#include <deal.II/base/partitioner.templates.h>
#include <deal.II/base/utilities.h>

#include <algorithm>
#include <cmath>

namespace mpm
{
  template <int dim>
  std::size_t BackgroundGrid<dim>::exchange_bytes_per_array(const std::size_t value_bytes) const
  {
    // Import sends each ghost entry to its owner, export sends it back.
    return 2 * value_bytes * partitioner->n_ghost_indices();
  }

  template <int dim>
  std::vector<unsigned int> BackgroundGrid<dim>::exchanged_local_nodes() const
  {
    return InterleavedExchange::packed_indices(*partitioner);
  }

  template <int dim>
  std::vector<unsigned int> BackgroundGrid<dim>::exchanged_local_cells() const
  {
    return InterleavedExchange::packed_indices(*cell_partitioner);
  }

  template <int dim>
  template <typename Real>
  void BackgroundGrid<dim>::sum_local_cells(Real *const *arrays, const int count) const
  {
    if (n_ranks > 1)
      cell_exchange.sum(cell_partitioner, arrays, count);
  }

  template <int dim>
  template <typename Real>
  void BackgroundGrid<dim>::sum_packed_nodes(Real *values, const int count) const
  {
    if (n_ranks > 1)
      node_exchange.sum_packed(partitioner, values, count);
  }

  template <int dim>
  template <typename Real>
  void BackgroundGrid<dim>::sum_packed_cells(Real *values, const int count) const
  {
    if (n_ranks > 1)
      cell_exchange.sum_packed(cell_partitioner, values, count);
  }

  namespace
  {
    template <typename Real>
    std::vector<Real> &buffer_of(std::vector<double> &d, std::vector<float> &f);
    template <>
    std::vector<double> &buffer_of<double>(std::vector<double> &d, std::vector<float> &)
    {
      return d;
    }
    template <>
    std::vector<float> &buffer_of<float>(std::vector<double> &, std::vector<float> &f)
    {
      return f;
    }
  } // namespace

  // The Partitioner's raw-array exchange (InterleavedExchange), as
  // LinearAlgebra::distributed::Vector's compress(add) + update_ghost_values() do
  // internally, but without the vector's ghosted/non-ghosted state (writing into ghost
  // entries of a vector in the ghosted state and then compressing is what deal.II forbids):
  //   import: ghost entries are added into their owners' entries, then zeroed;
  //   export: owners' sums are copied into every rank's ghost entries.
  template <int dim>
  template <typename Real>
  void BackgroundGrid<dim>::sum_nodal(Real *const *arrays, const int count) const
  {
    if (n_ranks == 1)
      return;
    node_exchange.sum(partitioner, arrays, count);
  }

  // Cells: gather the owned and ghost cells' entries into the partitioner's layout,
  // exchange as for the nodes, scatter back. Each rank's cell sums then hold all points
  // of the cell, on whichever rank they are.
  template <int dim>
  template <typename Real>
  void BackgroundGrid<dim>::sum_cells(Real *const *arrays, const int count) const
  {
    if (n_ranks == 1)
      return;
    const std::size_t  n_local = lattice_cell_of_local_cell_index.size();
    std::vector<Real> &buffer  = buffer_of<Real>(cell_buffer_double, cell_buffer_float);
    buffer.resize(count * n_local);
    std::vector<Real *> local(count);
    for (int i = 0; i < count; ++i)
      {
        local[i] = buffer.data() + i * n_local;
        for (std::size_t c = 0; c < n_local; ++c)
          local[i][c] = lattice_cell_of_local_cell_index[c] < 0 ? Real(0) : arrays[i][lattice_cell_of_local_cell_index[c]];
      }
    cell_exchange.sum(cell_partitioner, local.data(), count);
    for (int i = 0; i < count; ++i)
      for (std::size_t c = 0; c < n_local; ++c)
        if (lattice_cell_of_local_cell_index[c] >= 0) // not a coarse cell's
          arrays[i][lattice_cell_of_local_cell_index[c]] = local[i][c];
  }

  template std::size_t BackgroundGrid<2>::exchange_bytes_per_array(std::size_t) const;
  template std::vector<unsigned int> BackgroundGrid<2>::exchanged_local_nodes() const;
  template std::vector<unsigned int> BackgroundGrid<2>::exchanged_local_cells() const;
  template std::size_t BackgroundGrid<3>::exchange_bytes_per_array(std::size_t) const;
  template std::vector<unsigned int> BackgroundGrid<3>::exchanged_local_nodes() const;
  template std::vector<unsigned int> BackgroundGrid<3>::exchanged_local_cells() const;
  template void BackgroundGrid<2>::sum_nodal(double *const *, int) const;
  template void BackgroundGrid<3>::sum_nodal(double *const *, int) const;
  template void BackgroundGrid<2>::sum_nodal(float *const *, int) const;
  template void BackgroundGrid<3>::sum_nodal(float *const *, int) const;
  template void BackgroundGrid<2>::sum_local_cells(double *const *, int) const;
  template void BackgroundGrid<3>::sum_local_cells(double *const *, int) const;
  template void BackgroundGrid<2>::sum_cells(double *const *, int) const;
  template void BackgroundGrid<3>::sum_cells(double *const *, int) const;
  template void BackgroundGrid<2>::sum_cells(float *const *, int) const;
  template void BackgroundGrid<3>::sum_cells(float *const *, int) const;
  template void BackgroundGrid<2>::sum_packed_nodes(double *, int) const;
  template void BackgroundGrid<3>::sum_packed_nodes(double *, int) const;
  template void BackgroundGrid<2>::sum_packed_nodes(float *, int) const;
  template void BackgroundGrid<3>::sum_packed_nodes(float *, int) const;
  template void BackgroundGrid<2>::sum_packed_cells(double *, int) const;
  template void BackgroundGrid<3>::sum_packed_cells(double *, int) const;
  template void BackgroundGrid<2>::sum_packed_cells(float *, int) const;
  template void BackgroundGrid<3>::sum_packed_cells(float *, int) const;
} // namespace mpm
