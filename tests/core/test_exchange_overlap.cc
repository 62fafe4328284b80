// Which points may run while the ranks' exchange travels (exchange_overlap.h):
// - cells_reaching_exchange equals the flags found by looking at every cell's windows
//   directly, on random lattices and random exchanged nodes and cells (2D and 3D);
// - the premise of the overlap: a point of an unflagged home cell, anywhere up to its
//   shape's safe distance outside that cell (migration.h) and with any domain up to a cell,
//   has no node of its stencil (every stencil position, the B-splines' folding at the
//   lattice's faces included) among the exchanged nodes, and after a further move of up to
//   one cell its cell is not an exchanged cell: linear, GIMP, quadratic and cubic B-splines;
// - point_range views the same values as the whole view.
// The node window or the cell window one layer narrower at its upper end makes
// the premise fail (tried; both have a layer to spare at their lower ends).
#include <mpm/core/exchange_overlap.h>
#include <mpm/core/host_storage.h>
#include <mpm/core/migration.h>
#include <mpm/core/shape_functions.h>

#include "check.h"

#include <cmath>
#include <random>
#include <vector>

namespace
{
  using namespace mpm;
  using mpm_test::check;

  template <int dim>
  long lattice_index(const int coordinates[dim], const int sizes[dim])
  {
    long index = 0;
    for (int d = dim - 1; d >= 0; --d)
      index = index * sizes[d] + coordinates[d];
    return index;
  }

  template <int dim>
  bool inside(const int coordinates[dim], const int sizes[dim])
  {
    for (int d = 0; d < dim; ++d)
      if (coordinates[d] < 0 || coordinates[d] >= sizes[d])
        return false;
    return true;
  }

  // visit(k) for every k of the box lower[d] <= k[d] < lower[d] + width[d].
  template <int dim, typename Visit>
  void for_each_in_box(const int lower[dim], const int width[dim], Visit &&visit)
  {
    long n = 1;
    for (int d = 0; d < dim; ++d)
      n *= width[d];
    for (long o = 0; o < n; ++o)
      {
        int  k[dim];
        long r = o;
        for (int d = 0; d < dim; ++d)
          {
            k[d] = lower[d] + static_cast<int>(r % width[d]);
            r /= width[d];
          }
        visit(k);
      }
  }

  // Random exchanged nodes and cells: a few random boxes of them (as a partition's
  // boundary makes layers), nodes and cells in boxes of their own.
  template <int dim>
  void random_exchange(std::mt19937 &random, const int n_cells[dim], std::vector<long> &nodes,
                       std::vector<long> &cells)
  {
    int node_sizes[dim];
    for (int d = 0; d < dim; ++d)
      node_sizes[d] = n_cells[d] + 1;
    nodes.clear();
    cells.clear();
    std::uniform_int_distribution<int> coin(0, 99);
    for (int c = 0; c < (dim == 2 ? 30 : 12); ++c)
      {
        int lo[3] = {0, 0, 0}, hi[3] = {0, 0, 0};
        for (int d = 0; d < dim; ++d)
          {
            lo[d] = std::uniform_int_distribution<int>(0, n_cells[d])(random);
            hi[d] = std::min(n_cells[d], lo[d] + std::uniform_int_distribution<int>(0, 2)(random));
          }
        int k[3];
        for (k[2] = lo[2]; k[2] <= hi[2]; ++k[2])
          for (k[1] = lo[1]; k[1] <= hi[1]; ++k[1])
            for (k[0] = lo[0]; k[0] <= hi[0]; ++k[0])
              {
                // Nodes for the even boxes, cells (apart from any exchanged node) for the odd.
                if (c % 2 == 0)
                  nodes.push_back(lattice_index<dim>(k, node_sizes));
                else if (inside<dim>(k, n_cells) && coin(random) < 50)
                  cells.push_back(lattice_index<dim>(k, n_cells));
              }
      }
  }

  // The flags by brute force: every cell's node and cell windows looked at directly.
  template <int dim>
  std::vector<std::uint8_t> flags_directly(const int n_cells[dim], const std::vector<long> &nodes,
                                           const std::vector<long> &cells)
  {
    int  node_sizes[dim];
    long n_nodes = 1, n_all_cells = 1;
    for (int d = 0; d < dim; ++d)
      {
        node_sizes[d] = n_cells[d] + 1;
        n_nodes *= node_sizes[d];
        n_all_cells *= n_cells[d];
      }
    std::vector<std::uint8_t> is_node(n_nodes, 0), is_cell(n_all_cells, 0), flags(n_all_cells, 0);
    for (const long l : nodes)
      is_node[l] = 1;
    for (const long c : cells)
      is_cell[c] = 1;
    for (long c = 0; c < n_all_cells; ++c)
      {
        int  home[dim];
        long rest = c;
        for (int d = 0; d < dim; ++d)
          {
            home[d] = static_cast<int>(rest % n_cells[d]);
            rest /= n_cells[d];
          }
        auto any_in_window = [&](const int lower, const int upper, const int sizes[dim],
                                 const std::vector<std::uint8_t> &marks) {
          int from[dim], width[dim];
          for (int d = 0; d < dim; ++d)
            {
              from[d]  = home[d] + lower;
              width[d] = upper - lower + 1;
            }
          bool any = false;
          for_each_in_box<dim>(from, width, [&](const int k[dim]) {
            any = any || (inside<dim>(k, sizes) && marks[lattice_index<dim>(k, sizes)]);
          });
          return any;
        };
        flags[c] = any_in_window(overlap_node_window_lower, overlap_node_window_upper, node_sizes, is_node) ||
                   any_in_window(overlap_cell_window_lower, overlap_cell_window_upper, n_cells, is_cell);
      }
    return flags;
  }

  // Points of unflagged home cells reach no exchanged entry; returns how many points were
  // placed in unflagged cells.
  template <int dim, typename Shape>
  long check_premise(std::mt19937 &random, const int n_cells[dim], const std::vector<std::uint8_t> &flags,
                     const std::vector<long> &nodes, const std::vector<long> &cells, const ShapeFunction shape,
                     const char *name)
  {
    int  node_sizes[dim];
    long n_nodes = 1;
    for (int d = 0; d < dim; ++d)
      {
        node_sizes[d] = n_cells[d] + 1;
        n_nodes *= node_sizes[d];
      }
    std::vector<std::uint8_t> is_node(n_nodes, 0), is_cell(flags.size(), 0);
    for (const long l : nodes)
      is_node[l] = 1;
    for (const long c : cells)
      is_cell[c] = 1;
    const double                           safe = safe_distance_outside_home_cell(shape);
    std::uniform_real_distribution<double> unit(0, 1);
    std::uniform_int_distribution<long>    pick(0, static_cast<long>(flags.size()) - 1);
    long                                   placed = 0, reached = 0;
    for (int trial = 0; trial < 20000; ++trial)
      {
        const long c = pick(random);
        if (flags[c])
          continue;
        ++placed;
        int  home[dim];
        long rest = c;
        for (int d = 0; d < dim; ++d)
          {
            home[d] = static_cast<int>(rest % n_cells[d]);
            rest /= n_cells[d];
          }
        // Position in cell units: in the home cell widened by the safe distance (its bounds
        // included, a tenth of the trials), domain up to a whole cell.
        double s[dim];
        int    first[dim];
        for (int d = 0; d < dim; ++d)
          {
            const double u = unit(random);
            s[d]           = trial % 10 == 0 ? (u < 0.5 ? home[d] - safe : home[d] + 1 + safe) :
                                               home[d] - safe + (1 + 2 * safe) * u;
            double w[Shape::n_per_direction], dw[Shape::n_per_direction];
            stencil_weights_1d<Shape>(s[d], 0.01 + 0.99 * unit(random), n_cells[d], first[d], w, dw);
          }
        int n_per_direction[dim];
        for (int d = 0; d < dim; ++d)
          n_per_direction[d] = Shape::n_per_direction;
        for_each_in_box<dim>(first, n_per_direction, [&](const int k[dim]) {
          if (inside<dim>(k, node_sizes) && is_node[lattice_index<dim>(k, node_sizes)])
            ++reached;
        });
        // Every cell the point can be in after a further move of up to a cell.
        int lowest[dim], width[dim];
        for (int d = 0; d < dim; ++d)
          {
            lowest[d] = static_cast<int>(std::floor(s[d] - 1));
            width[d]  = static_cast<int>(std::floor(s[d] + 1)) - lowest[d] + 1;
          }
        for_each_in_box<dim>(lowest, width, [&](const int moved[dim]) {
          if (inside<dim>(moved, n_cells) && is_cell[lattice_index<dim>(moved, n_cells)])
            ++reached;
        });
      }
    std::printf("  %dD %s: %ld points in unflagged cells, %ld reached an exchanged entry\n", dim, name, placed,
                reached);
    check(reached == 0, "a point of an unflagged cell reaches no exchanged entry");
    return placed;
  }

  template <int dim>
  void check_lattices(std::mt19937 &random)
  {
    for (int trial = 0; trial < 6; ++trial)
      {
        int n_cells[dim];
        for (int d = 0; d < dim; ++d)
          n_cells[d] = std::uniform_int_distribution<int>(dim == 2 ? 20 : 12, dim == 2 ? 40 : 18)(random);
        std::vector<long> nodes, cells;
        random_exchange<dim>(random, n_cells, nodes, cells);
        const std::vector<std::uint8_t> flags = cells_reaching_exchange<dim>(n_cells, nodes, cells);
        check(flags == flags_directly<dim>(n_cells, nodes, cells), "cells_reaching_exchange = the windows directly");
        long n_flagged = 0;
        for (const std::uint8_t f : flags)
          n_flagged += f;
        check(n_flagged > 0 && n_flagged < static_cast<long>(flags.size()), "some cells flagged, some not");
        if (trial < 2)
          {
            long placed = 0;
            placed += check_premise<dim, LinearShape>(random, n_cells, flags, nodes, cells, ShapeFunction::linear,
                                                      "linear");
            placed += check_premise<dim, GimpShape>(random, n_cells, flags, nodes, cells, ShapeFunction::gimp, "GIMP");
            placed += check_premise<dim, QuadraticBSplineShape>(random, n_cells, flags, nodes, cells,
                                                                ShapeFunction::bspline2, "B-spline 2");
            placed += check_premise<dim, CubicBSplineShape>(random, n_cells, flags, nodes, cells,
                                                            ShapeFunction::bspline3, "B-spline 3");
            check(placed > 1000, "points were placed in unflagged cells");
          }
      }
  }

  void check_point_range()
  {
    HostPoints<3, double> points;
    points.set_n_state_variables(2);
    points.resize(10);
    for (int i = 0; i < 10; ++i)
      {
        points.position[2][i]          = i;
        points.stress[5][i]            = 10 + i;
        points.state_variables[1][i]   = 20 + i;
        points.material[i]             = i % 3;
        points.deformation_gradient[8][i] = 30 + i;
      }
    const PointsView<3, double> all = points.view(), part = point_range(all, 4, 5);
    bool same = part.n_points == 5 && part.n_state_variables == 2;
    for (int i = 0; i < 5; ++i)
      same = same && part.position[2][i] == 4 + i && part.stress[5][i] == 14 + i &&
             part.state_variables[1][i] == 24 + i && part.material[i] == (4 + i) % 3 &&
             part.deformation_gradient[8][i] == 34 + i;
    check(same, "point_range views points 4 .. 8");
  }
} // namespace

int main()
{
  std::mt19937 random(20261129);
  check_lattices<2>(random);
  check_lattices<3>(random);
  check_point_range();
  return mpm_test::finish("test_exchange_overlap");
}
