// Where deal.II's grid is fine on several ranks with Grid/Nodes = near material: the region
// around the points' blocks, and the cells flagged when the points leave it (BackgroundGrid,
// background_grid.h).
#include <mpm/dealii/background_grid.h>
#include <mpm/core/active_nodes.h>

#include <deal.II/base/partitioner.templates.h>
#include <deal.II/base/utilities.h>

#include <algorithm>
#include <cmath>

namespace mpm
{
  template <int dim>
  bool BackgroundGrid<dim>::meets_fine_region(const typename dealii::Triangulation<dim>::cell_iterator &cell) const
  {
    const int B = fine_block_cells;
    long      first[dim], lo[dim], hi[dim], nb[dim], n = 1;
    lower_lattice_corner(cell, first);
    const dealii::Point<dim> upper = cell->vertex(dealii::GeometryInfo<dim>::vertices_per_cell - 1);
    for (int d = 0; d < dim; ++d)
      {
        lo[d] = std::max(first[d] / B, fine_region_lower[d]);
        hi[d] = std::min((std::lround((upper[d] - origin[d]) / h) - 1) / B, fine_region_upper[d]);
        if (lo[d] > hi[d])
          return false;
        nb[d] = n_blocks_along<dim>(n_cells[d], B);
        n *= hi[d] - lo[d] + 1;
      }
    for (long j = 0; j < n; ++j)
      {
        long block = 0, rest = j, at[dim];
        for (int d = 0; d < dim; ++d)
          {
            at[d] = lo[d] + rest % (hi[d] - lo[d] + 1);
            rest /= hi[d] - lo[d] + 1;
          }
        for (int d = dim - 1; d >= 0; --d)
          block = block * nb[d] + at[d];
        if (fine_blocks[block] != 0)
          return true;
      }
    return false;
  }

  template <int dim>
  long BackgroundGrid<dim>::block_of(const double *x) const
  {
    return block_of_cell<dim>(lattice_cell_of(x), n_cells, fine_block_cells);
  }

  template <int dim>
  bool BackgroundGrid<dim>::fine_region_misses(const std::vector<long> &holding)
  {
    const int B = fine_block_cells;
    long      nb[dim];
    for (int d = 0; d < dim; ++d)
      nb[d] = n_blocks_along<dim>(n_cells[d], B);
    // The blocks within `reach` blocks (max-norm) of one in holding, ascending.
    const auto dilated = [&](const int reach) {
      std::vector<long> out;
      const int         width = 2 * reach + 1;
      for (const long b : holding)
        {
          long at[dim], rest = b;
          for (int d = 0; d < dim; ++d)
            {
              at[d] = rest % nb[d];
              rest /= nb[d];
            }
          for (int j = 0; j < dealii::Utilities::pow(width, dim); ++j)
            {
              long neighbour = 0;
              bool inside    = true;
              for (int d = dim - 1, r = j; d >= 0; --d)
                {
                  const int  step = dealii::Utilities::pow(width, d);
                  const long i    = at[d] - reach + r / step;
                  r %= step;
                  inside    = inside && i >= 0 && i < nb[d];
                  neighbour = neighbour * nb[d] + (inside ? i : 0);
                }
              if (inside)
                out.push_back(neighbour);
            }
        }
      std::sort(out.begin(), out.end());
      out.erase(std::unique(out.begin(), out.end()), out.end());
      return out;
    };
    const std::vector<long> kept = dilated(1);
    const bool miss = std::any_of(kept.begin(), kept.end(), [&](const long b) { return fine_blocks[b] == 0; });
    if (miss)
      for (const long b : dilated(2))
        {
          fine_blocks[b] = 1;
          long rest      = b;
          for (int d = 0; d < dim; ++d)
            {
              const long at = rest % nb[d];
              rest /= nb[d];
              fine_region_lower[d] = std::min(fine_region_lower[d], at);
              fine_region_upper[d] = std::max(fine_region_upper[d], at);
            }
        }
    return miss;
  }

  template <int dim>
  bool BackgroundGrid<dim>::flag_cells_to_refine()
  {
    int flagged = 0;
    for (const auto &cell : triangulation.active_cell_iterators())
      if (cell->is_locally_owned() && cell->level() < finest_level && meets_fine_region(cell))
        {
          cell->set_refine_flag();
          flagged = 1;
        }
    return dealii::Utilities::MPI::max(flagged, communicator) > 0;
  }

  template bool BackgroundGrid<2>::meets_fine_region(const typename dealii::Triangulation<2>::cell_iterator &) const;
  template long BackgroundGrid<2>::block_of(const double *) const;
  template bool BackgroundGrid<2>::fine_region_misses(const std::vector<long> &);
  template bool BackgroundGrid<2>::flag_cells_to_refine();
  template bool BackgroundGrid<3>::meets_fine_region(const typename dealii::Triangulation<3>::cell_iterator &) const;
  template long BackgroundGrid<3>::block_of(const double *) const;
  template bool BackgroundGrid<3>::fine_region_misses(const std::vector<long> &);
  template bool BackgroundGrid<3>::flag_cells_to_refine();
} // namespace mpm
