#include <mpm/dealii/interleaved_exchange.h>

#include <deal.II/base/array_view.h>
#include <deal.II/base/index_set.h>
#include <deal.II/base/partitioner.templates.h>

#include <algorithm>
#include <cstring>
#include <limits>
#include <string>

namespace mpm
{
  template <>
  InterleavedExchange::Buffers<double> &InterleavedExchange::buffers<double>()
  {
    return doubles;
  }
  template <>
  InterleavedExchange::Buffers<float> &InterleavedExchange::buffers<float>()
  {
    return floats;
  }

  const dealii::Utilities::MPI::Partitioner &InterleavedExchange::interleaved(const int count)
  {
    auto &made = by_count[count];
    if (made == nullptr)
      {
        const auto                            range = base->local_range();
        const dealii::types::global_dof_index n     = base->size();
        AssertThrow(n <= std::numeric_limits<dealii::types::global_dof_index>::max() / count,
                    dealii::ExcMessage("The grid has too many nodes or cells for deal.II's index type to number " +
                                       std::to_string(count) + " interleaved arrays of them; configure deal.II with "
                                       "64-bit indices (DEAL_II_WITH_64BIT_INDICES)."));
        dealii::IndexSet owned(n * count), ghosts(n * count);
        owned.add_range(range.first * count, range.second * count);
        std::vector<dealii::types::global_dof_index> ghost_list;
        ghost_list.reserve(base->n_ghost_indices() * count);
        for (const auto g : base->ghost_indices())
          for (int k = 0; k < count; ++k)
            ghost_list.push_back(g * count + k);
        ghosts.add_indices(ghost_list.begin(), ghost_list.end());
        owned.compress();
        ghosts.compress();
        made = std::make_unique<dealii::Utilities::MPI::Partitioner>(owned, ghosts, base->get_mpi_communicator());
      }
    return *made;
  }

  std::vector<unsigned int> InterleavedExchange::packed_indices(const dealii::Utilities::MPI::Partitioner &base)
  {
    std::vector<unsigned int> local;
    for (const auto &range : base.import_indices())
      for (unsigned int i = range.first; i < range.second; ++i)
        local.push_back(i);
    std::sort(local.begin(), local.end());
    local.erase(std::unique(local.begin(), local.end()), local.end());
    const unsigned int n_owned = base.locally_owned_size();
    for (unsigned int g = 0; g < base.n_ghost_indices(); ++g)
      local.push_back(n_owned + g);
    return local;
  }

  void InterleavedExchange::set_base(const std::shared_ptr<const dealii::Utilities::MPI::Partitioner> &grid_partitioner)
  {
    if (grid_partitioner == base)
      return;
    base = grid_partitioner;
    by_count.clear();
    import_local.clear();
    for (const auto &range : base->import_indices())
      for (unsigned int i = range.first; i < range.second; ++i)
        import_local.push_back(i);
    import_unique = import_local;
    std::sort(import_unique.begin(), import_unique.end());
    import_unique.erase(std::unique(import_unique.begin(), import_unique.end()), import_unique.end());
  }

  template <typename Real>
  void InterleavedExchange::import_and_export(const dealii::Utilities::MPI::Partitioner &p, Real *const owned,
                                              Real *const ghost, const int count)
  {
    const std::size_t n_owned = base->locally_owned_size(), n_ghost = base->n_ghost_indices();
    Buffers<Real>    &b       = buffers<Real>();
    b.temp.resize(p.n_import_indices());
    requests.clear();
    using dealii::ArrayView;
    const ArrayView<Real> owned_view(owned, n_owned * count), ghost_view(ghost, n_ghost * count),
      temp_view(b.temp.data(), b.temp.size());
    p.import_from_ghosted_array_start(dealii::VectorOperation::add, 0, ghost_view, temp_view, requests);
    p.import_from_ghosted_array_finish(dealii::VectorOperation::add, ArrayView<const Real>(b.temp.data(), b.temp.size()),
                                       owned_view, ghost_view, requests);
    p.export_to_ghosted_array_start(0, ArrayView<const Real>(owned, n_owned * count), temp_view, ghost_view,
                                    requests);
    p.export_to_ghosted_array_finish(ghost_view, requests);
  }

  template <typename Real>
  void InterleavedExchange::sum(const std::shared_ptr<const dealii::Utilities::MPI::Partitioner> &grid_partitioner,
                                Real *const *arrays, const int count)
  {
    set_base(grid_partitioner);
    const dealii::Utilities::MPI::Partitioner &p = interleaved(count);
    const std::size_t n_owned = base->locally_owned_size(), n_ghost = base->n_ghost_indices();
    Buffers<Real>    &b       = buffers<Real>();
    if (b.owned_size < n_owned * count)
      {
        b.owned.reset(new Real[n_owned * count]);
        b.owned_size = n_owned * count;
      }
    b.ghost.resize(n_ghost * count);

    Real *const owned = b.owned.get();
    for (std::size_t j = 0; j < n_ghost; ++j)
      for (int k = 0; k < count; ++k)
        b.ghost[j * count + k] = arrays[k][n_owned + j];
    for (const unsigned int i : import_local)
      for (int k = 0; k < count; ++k)
        owned[std::size_t(i) * count + k] = arrays[k][i];

    import_and_export(p, owned, b.ghost.data(), count);

    for (const unsigned int i : import_local)
      for (int k = 0; k < count; ++k)
        arrays[k][i] = owned[std::size_t(i) * count + k];
    for (std::size_t j = 0; j < n_ghost; ++j)
      for (int k = 0; k < count; ++k)
        arrays[k][n_owned + j] = b.ghost[j * count + k];
  }

  template <typename Real>
  void InterleavedExchange::sum_packed(const std::shared_ptr<const dealii::Utilities::MPI::Partitioner> &grid_partitioner,
                                       Real *const values, const int count)
  {
    set_base(grid_partitioner);
    const dealii::Utilities::MPI::Partitioner &p = interleaved(count);
    const std::size_t n_owned = base->locally_owned_size();
    Buffers<Real>    &b       = buffers<Real>();
    if (b.owned_size < n_owned * count)
      {
        b.owned.reset(new Real[n_owned * count]);
        b.owned_size = n_owned * count;
      }
    Real *const       owned    = b.owned.get();
    const std::size_t n_unique = import_unique.size();
    for (std::size_t j = 0; j < n_unique; ++j)
      std::memcpy(owned + std::size_t(import_unique[j]) * count, values + j * count, count * sizeof(Real));
    // The ghosts are the packed values' tail, already interleaved.
    import_and_export(p, owned, values + n_unique * count, count);
    for (std::size_t j = 0; j < n_unique; ++j)
      std::memcpy(values + j * count, owned + std::size_t(import_unique[j]) * count, count * sizeof(Real));
  }

  template void InterleavedExchange::sum(const std::shared_ptr<const dealii::Utilities::MPI::Partitioner> &,
                                         double *const *, int);
  template void InterleavedExchange::sum(const std::shared_ptr<const dealii::Utilities::MPI::Partitioner> &,
                                         float *const *, int);
  template void InterleavedExchange::sum_packed(const std::shared_ptr<const dealii::Utilities::MPI::Partitioner> &,
                                                double *, int);
  template void InterleavedExchange::sum_packed(const std::shared_ptr<const dealii::Utilities::MPI::Partitioner> &,
                                                float *, int);
} // namespace mpm
