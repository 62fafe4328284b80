// The partition the grid is built with (BackgroundGrid given the start points) is the partition
// by the points' work: repartitioning by the same weights moves no cell. p4est partitions after
// each level of the global refinement, and deal.II asks for the weight of each child of a cell
// being refined with the parent's iterator; the grid must give each child its own cells' work.
// Points piled unevenly (denser towards one corner, empty elsewhere), 2D and 3D, coarse cells
// refined from one coarse cell (6 levels in 2D, 4 in 3D), and deal.II cells of several lattice
// cells (Grid/Cells per deal.II cell: 4 in 2D, 2 in 3D); run on 2 and 3 ranks.
#include <mpm/dealii/background_grid.h>

#include <deal.II/base/mpi.h>

#include <algorithm>
#include <cmath>
#include <iostream>
#include <vector>

#include "box_scene.h"

namespace
{
  using namespace dealii;

  template <int dim>
  std::vector<long> owned_lattice_cells(const mpm::BackgroundGrid<dim> &grid)
  {
    std::vector<long> cells;
    for (const auto &cell : grid.triangulation.active_cell_iterators())
      if (cell->is_locally_owned())
        grid.for_each_lattice_cell(cell, [&](const long c) { cells.push_back(c); });
    std::sort(cells.begin(), cells.end());
    return cells;
  }

  // Returns the number of cells that changed owner (summed over ranks).
  template <int dim>
  unsigned int cells_moved_by_repartition(const unsigned int cells_per_direction, const int cells_per_grid_cell = 1)
  {
    mpm::Parameters p          = mpm_test::box_domain<dim>(1.0, 1.0 / cells_per_direction);
    p.parallel.load_balance_threshold   = 1.02;
    p.cells_per_grid_cell      = cells_per_grid_cell;
    const double point_weight  = p.parallel.point_weight;
    // A pile: in the lattice cells with x_0 + x_1 < 1 (the others empty), more points towards
    // the origin, away from the cells' faces (each point's cell is unambiguous).
    mpm::HostPoints<dim, double> points;
    std::vector<double>          x[dim];
    const double                 h = 1.0 / cells_per_direction;
    const long                   n = std::lround(std::pow(cells_per_direction, dim));
    for (long c = 0; c < n; ++c)
      {
        long   rest = c;
        double center[dim];
        for (int d = 0; d < dim; ++d)
          {
            center[d] = (rest % cells_per_direction + 0.5) * h;
            rest /= cells_per_direction;
          }
        if (center[0] + center[1] >= 1)
          continue;
        const int in_cell = 1 + static_cast<int>(6 * (1 - center[0] - center[1]));
        for (int k = 0; k < in_cell; ++k)
          for (int d = 0; d < dim; ++d)
            x[d].push_back(center[d] + 0.3 * h * ((k + d) % 3 - 1));
      }
    points.resize(static_cast<int>(x[0].size()));
    for (int d = 0; d < dim; ++d)
      std::copy(x[d].begin(), x[d].end(), points.position[d].begin());

    mpm::BackgroundGrid<dim> grid(p, MPI_COMM_WORLD, {&points});
    const std::vector<long>  built = owned_lattice_cells(grid);

    // The repartition's weights (MaterialPoints' for the points in their cells).
    std::vector<unsigned int> points_in_cell(n, 0);
    for (int i = 0; i < points.size(); ++i)
      {
        double xi[dim];
        for (int d = 0; d < dim; ++d)
          xi[d] = points.position[d][i];
        ++points_in_cell[grid.lattice_cell_of(xi)];
      }
    auto connection = grid.triangulation.signals.weight.connect(
      [&](const typename Triangulation<dim>::cell_iterator &cell,
          const typename Triangulation<dim>::CellStatus) -> unsigned int {
        unsigned int in_cell = 0;
        grid.for_each_lattice_cell(cell, [&](const long c) { in_cell += points_in_cell[c]; });
        return mpm::cell_partition_weight(in_cell, point_weight, grid.lattice_cells_per_grid_cell);
      });
    grid.distributed->repartition();
    connection.disconnect();
    const std::vector<long> after = owned_lattice_cells(grid);

    std::vector<long> changed;
    std::set_symmetric_difference(built.begin(), built.end(), after.begin(), after.end(),
                                  std::back_inserter(changed));
    const unsigned int moved = Utilities::MPI::sum(static_cast<unsigned int>(changed.size()), MPI_COMM_WORLD) / 2;
    const unsigned int cells = Utilities::MPI::sum(static_cast<unsigned int>(built.size()), MPI_COMM_WORLD);
    if (Utilities::MPI::this_mpi_process(MPI_COMM_WORLD) == 0)
      std::cout << dim << "D, " << cells << " cells (deal.II cells of " << grid.lattice_cells_per_grid_cell
                << "), " << points.size() << " points: " << moved
                << " cells change rank in a repartition after the build" << std::endl;
    return moved;
  }
} // namespace

int main(int argc, char **argv)
{
  Utilities::MPI::MPI_InitFinalize mpi(argc, argv, 1);
  if (Utilities::MPI::n_mpi_processes(MPI_COMM_WORLD) < 2)
    {
      std::cerr << "test_build_partition: run on 2 or more ranks" << std::endl;
      return 1;
    }
  unsigned int moved = 0;
  moved += cells_moved_by_repartition<2>(64); // one coarse cell refined 6 times
  moved += cells_moved_by_repartition<3>(16); // 4 times
  moved += cells_moved_by_repartition<2>(64, 4); // one coarse cell of 16 x 16 deal.II cells of 4 x 4
  moved += cells_moved_by_repartition<3>(16, 2); // 8^3 deal.II cells of 2^3
  if (Utilities::MPI::this_mpi_process(MPI_COMM_WORLD) == 0)
    std::cout << (moved == 0 ? "ok" : "FAILED") << std::endl;
  return moved == 0 ? 0 : 1;
}
