// InterleavedExchange (include/mpm/dealii/interleaved_exchange.h), two ways:
// - against deal.II's own distributed vector: every rank writes a value into each of its owned
//   and ghost nodes (and cells), the exchange sums them, and the result must equal what
//   LinearAlgebra::distributed::Vector's compress(add) + update_ghost_values() give for each
//   array alone. Values are small integers, so every sum is exact whatever its order: the
//   comparison is exact;
// - against the Partitioner's exchange of one array at a time, on random values: equal to the
//   bit (the sums are added in the same order);
// - sum_packed (the GPU engine's path) against sum(): the same bits at every exchanged entry.
// Counts 1, 3 and 7 (MUSL's first exchange), double and float, a repartitioned grid, in 2D
// and 3D; meant for 1 to 4 ranks.
#include <mpm/dealii/interleaved_exchange.h>

#include <deal.II/base/array_view.h>
#include <deal.II/base/mpi.h>
#include <deal.II/base/partitioner.templates.h>
#include <deal.II/distributed/tria.h>
#include <deal.II/dofs/dof_handler.h>
#include <deal.II/dofs/dof_tools.h>
#include <deal.II/fe/fe_q.h>
#include <deal.II/grid/grid_generator.h>
#include <deal.II/lac/la_parallel_vector.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <random>
#include <memory>
#include <string>
#include <vector>

using namespace dealii;

namespace
{
  int failures = 0;

  // Rank r's contribution of array k at global index g.
  double contribution(const types::global_dof_index g, const unsigned int r, const int k)
  {
    return static_cast<double>((g % 97) + 101 * k + 1009 * r + 1);
  }

  template <typename Real>
  void check(const std::shared_ptr<const Utilities::MPI::Partitioner> &partitioner, mpm::InterleavedExchange &exchange,
             const int count, const char *what)
  {
    const MPI_Comm     comm    = partitioner->get_mpi_communicator();
    const unsigned int rank    = Utilities::MPI::this_mpi_process(comm);
    const std::size_t  n_owned = partitioner->locally_owned_size();
    const std::size_t  n_local = n_owned + partitioner->n_ghost_indices();

    std::vector<std::vector<Real>> arrays(count, std::vector<Real>(n_local));
    std::vector<Real *>            pointers(count);
    for (int k = 0; k < count; ++k)
      {
        for (std::size_t i = 0; i < n_local; ++i)
          arrays[k][i] = static_cast<Real>(contribution(partitioner->local_to_global(i), rank, k));
        pointers[k] = arrays[k].data();
      }
    exchange.sum(partitioner, pointers.data(), count);

    double worst = 0;
    for (int k = 0; k < count; ++k)
      {
        LinearAlgebra::distributed::Vector<Real> reference(partitioner);
        for (std::size_t i = 0; i < n_local; ++i)
          reference.local_element(i) = static_cast<Real>(contribution(partitioner->local_to_global(i), rank, k));
        reference.compress(VectorOperation::add);
        reference.update_ghost_values();
        for (std::size_t i = 0; i < n_local; ++i)
          worst = std::max(worst, std::abs(double(arrays[k][i]) - double(reference.local_element(i))));
      }
    worst = Utilities::MPI::max(worst, comm);
    const bool ok = worst == 0;
    failures += ok ? 0 : 1;
    if (rank == 0)
      std::printf("%s %s, %d array(s), %s: largest difference from deal.II's vector %g\n", ok ? "ok  " : "FAIL", what,
                  count, sizeof(Real) == 8 ? "double" : "float", worst);
  }

  // The Partitioner's exchange of one array (owned entries, then ghosts), as deal.II's vector
  // does it inside compress(add) + update_ghost_values().
  template <typename Real>
  void one_array_exchange(const Utilities::MPI::Partitioner &p, std::vector<Real> &array)
  {
    const unsigned int       n_owned = p.locally_owned_size();
    std::vector<Real>        temp(p.n_import_indices());
    std::vector<MPI_Request> requests;
    const ArrayView<Real>    owned(array.data(), n_owned), ghost(array.data() + n_owned, p.n_ghost_indices()),
      buffer(temp.data(), temp.size());
    p.import_from_ghosted_array_start(VectorOperation::add, 0, ghost, buffer, requests);
    p.import_from_ghosted_array_finish(VectorOperation::add, ArrayView<const Real>(temp.data(), temp.size()), owned,
                                       ghost, requests);
    p.export_to_ghosted_array_start(0, ArrayView<const Real>(array.data(), n_owned), buffer, ghost, requests);
    p.export_to_ghosted_array_finish(ghost, requests);
  }

  // count arrays over a partitioner's local storage, random in [-1, 1), seeded by rank.
  template <typename Real>
  std::vector<std::vector<Real>> random_arrays(const Utilities::MPI::Partitioner &partitioner, const int count,
                                               const unsigned int seed)
  {
    const std::size_t n_local = partitioner.locally_owned_size() + partitioner.n_ghost_indices();
    std::mt19937      random(seed + Utilities::MPI::this_mpi_process(partitioner.get_mpi_communicator()));
    std::uniform_real_distribution<double> value(-1, 1);
    std::vector<std::vector<Real>>         arrays(count, std::vector<Real>(n_local));
    for (auto &array : arrays)
      for (Real &v : array)
        v = static_cast<Real>(value(random));
    return arrays;
  }

  template <typename Real>
  std::vector<Real *> pointers_to(std::vector<std::vector<Real>> &arrays)
  {
    std::vector<Real *> pointers;
    for (auto &array : arrays)
      pointers.push_back(array.data());
    return pointers;
  }

  template <typename Real>
  void check_bitwise(const std::shared_ptr<const Utilities::MPI::Partitioner> &partitioner,
                     mpm::InterleavedExchange &exchange, const int count, const char *what)
  {
    const MPI_Comm     comm    = partitioner->get_mpi_communicator();
    const unsigned int rank    = Utilities::MPI::this_mpi_process(comm);
    const std::size_t  n_local = partitioner->locally_owned_size() + partitioner->n_ghost_indices();
    std::vector<std::vector<Real>> arrays = random_arrays<Real>(*partitioner, count, 1234), alone = arrays;
    std::vector<Real *>            pointers = pointers_to(arrays);
    exchange.sum(partitioner, pointers.data(), count);
    long differing = 0;
    for (int k = 0; k < count; ++k)
      {
        one_array_exchange(*partitioner, alone[k]);
        for (std::size_t i = 0; i < n_local; ++i)
          differing += std::memcmp(&alone[k][i], &arrays[k][i], sizeof(Real)) != 0 ? 1 : 0;
      }
    differing = Utilities::MPI::sum(differing, comm);
    failures += differing == 0 ? 0 : 1;
    if (rank == 0)
      std::printf("%s %s, %d array(s), %s, random values: %ld entries differ from the one-array exchange\n",
                  differing == 0 ? "ok  " : "FAIL", what, count, sizeof(Real) == 8 ? "double" : "float", differing);
  }

  // sum_packed (the GPU engine's path: only the exchanged entries, packed entry by entry)
  // against sum() on the whole arrays: the same bits at every exchanged entry.
  template <typename Real>
  void check_packed(const std::shared_ptr<const Utilities::MPI::Partitioner> &partitioner,
                    mpm::InterleavedExchange &exchange, const int count, const char *what)
  {
    const MPI_Comm     comm    = partitioner->get_mpi_communicator();
    const unsigned int rank    = Utilities::MPI::this_mpi_process(comm);
    const std::size_t  n_local = partitioner->locally_owned_size() + partitioner->n_ghost_indices();
    std::vector<std::vector<Real>> arrays   = random_arrays<Real>(*partitioner, count, 4321);
    std::vector<Real *>            pointers = pointers_to(arrays);
    const std::vector<unsigned int> packed_at = mpm::InterleavedExchange::packed_indices(*partitioner);
    std::vector<Real>               packed(packed_at.size() * count);
    for (std::size_t j = 0; j < packed_at.size(); ++j)
      for (int k = 0; k < count; ++k)
        packed[j * count + k] = arrays[k][packed_at[j]];
    exchange.sum(partitioner, pointers.data(), count);
    exchange.sum_packed(partitioner, packed.data(), count);
    // Every entry the exchange changes must be among the packed ones.
    long differing = 0, missing = 0;
    std::vector<char> is_packed(n_local, 0);
    for (const unsigned int i : packed_at)
      is_packed[i] = 1;
    for (std::size_t i = partitioner->locally_owned_size(); i < n_local; ++i)
      missing += is_packed[i] ? 0 : 1;
    for (std::size_t j = 0; j < packed_at.size(); ++j)
      for (int k = 0; k < count; ++k)
        differing += std::memcmp(&packed[j * count + k], &arrays[k][packed_at[j]], sizeof(Real)) != 0 ? 1 : 0;
    differing = Utilities::MPI::sum(differing + missing, comm);
    failures += differing == 0 ? 0 : 1;
    if (rank == 0)
      std::printf("%s %s, %d array(s), %s, packed: %ld entries differ from sum() or are not packed\n",
                  differing == 0 ? "ok  " : "FAIL", what, count, sizeof(Real) == 8 ? "double" : "float", differing);
  }

  template <int dim>
  void run(const MPI_Comm comm)
  {
    parallel::distributed::Triangulation<dim> triangulation(comm);
    GridGenerator::subdivided_hyper_cube(triangulation, 6);
    triangulation.refine_global(1);
    DoFHandler<dim> dof_handler(triangulation);
    const FE_Q<dim> fe(1);

    mpm::InterleavedExchange nodes, cells;
    for (int pass = 0; pass < 2; ++pass)
      {
        dof_handler.distribute_dofs(fe);
        IndexSet relevant;
        DoFTools::extract_locally_relevant_dofs(dof_handler, relevant);
        const auto node_partitioner =
          std::make_shared<Utilities::MPI::Partitioner>(dof_handler.locally_owned_dofs(), relevant, comm);
        const auto cell_partitioner = triangulation.global_active_cell_index_partitioner().lock();
        const std::string grid = std::to_string(dim) + "D " + (pass == 0 ? "grid" : "repartitioned grid");
        for (const int count : {1, 3, 7})
          {
            check<double>(node_partitioner, nodes, count, (grid + ", nodes").c_str());
            check<double>(cell_partitioner, cells, count, (grid + ", cells").c_str());
          }
        check<float>(node_partitioner, nodes, 7, (grid + ", nodes").c_str());
        check_bitwise<double>(node_partitioner, nodes, 7, (grid + ", nodes").c_str());
        check_bitwise<double>(cell_partitioner, cells, 2, (grid + ", cells").c_str());
        check_bitwise<float>(node_partitioner, nodes, 3, (grid + ", nodes").c_str());
        check_packed<double>(node_partitioner, nodes, 7, (grid + ", nodes").c_str());
        check_packed<double>(cell_partitioner, cells, 2, (grid + ", cells").c_str());
        check_packed<double>(node_partitioner, nodes, 1, (grid + ", nodes").c_str());
        // Backend = cuda in float on several ranks exchanges its packed entries in float.
        check_packed<float>(node_partitioner, nodes, 7, (grid + ", nodes").c_str());
        check_packed<float>(cell_partitioner, cells, 2, (grid + ", cells").c_str());
        // Refine a corner and let p4est repartition: new numbering, new neighbours.
        for (const auto &cell : triangulation.active_cell_iterators())
          if (cell->is_locally_owned() && cell->center()[0] < 0.2)
            cell->set_refine_flag();
        triangulation.execute_coarsening_and_refinement();
      }
  }
} // namespace

int main(int argc, char **argv)
{
  Utilities::MPI::MPI_InitFinalize mpi(argc, argv, 1);
  run<2>(MPI_COMM_WORLD);
  run<3>(MPI_COMM_WORLD);
  return failures == 0 ? 0 : 1;
}
