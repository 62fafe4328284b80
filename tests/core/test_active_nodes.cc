// The nodes near the material (active_nodes.h), on lattices whose sizes are not multiples
// of the block, for block sizes 1-5, in 2D and 3D:
// - enough: a point anywhere within active_node_margin cells (max-norm) of the cell it was
//   in finds every node of its stencil active, for each shape function (GIMP at the largest
//   half-length, 1/2), the B-splines' folded ghost nodes included;
// - not more than the blocks promise: every active node lies within 2B cells of a live
//   point's cell (its block and the neighbouring blocks);
// - numbered in lattice order, the lookup and its inverse agreeing; removed points activate
//   nothing; the home cells are the points' lattice cells.
#include <mpm/core/active_nodes.h>

#include "check.h"

#include <algorithm>
#include <array>
#include <random>
#include <string>
#include <vector>

namespace
{
  using mpm_test::check;

  template <typename Shape>
  bool stencil_active(const double s_all[], const int dim, const int n_cells[], const std::vector<int> &lookup)
  {
    int    first[3], n = Shape::n_per_direction;
    double w[3][4], dw[4];
    for (int d = 0; d < dim; ++d)
      Shape::weights_1d(s_all[d], 0.5, first[d], w[d], dw);
    int total = 1;
    for (int d = 0; d < dim; ++d)
      total *= n;
    for (int k = 0; k < total; ++k)
      {
        long lattice = 0, stride = 1;
        bool nonzero = true;
        int  rest    = k;
        for (int d = 0; d < dim; ++d)
          {
            const int j = rest % n;
            rest /= n;
            nonzero = nonzero && w[d][j] != 0;
            // The B-splines fold a ghost node beyond a face into the face node and its
            // neighbour: both lie inside, so clamping to the lattice asks for those.
            int idx = first[d] + j;
            idx     = idx < 0 ? 0 : (idx > n_cells[d] ? n_cells[d] : idx);
            lattice += idx * stride;
            stride *= n_cells[d] + 1;
          }
        if (nonzero && lookup[lattice] < 0)
          return false;
      }
    return true;
  }

  template <int dim>
  void check_lattice(const int block, std::mt19937 &random)
  {
    const int    n_cells[3] = {23, 17, 11};
    const double origin[3]  = {-1.0, 0.5, 2.0};
    const double h          = 0.25;
    // A cluster, a few lone points and removed points far from both.
    std::vector<double> position[dim];
    std::vector<int>    material;
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    for (int i = 0; i < 60; ++i)
      {
        const bool lone = i % 10 == 0, removed = i % 13 == 0;
        for (int d = 0; d < dim; ++d)
          {
            const double cells = lone ? n_cells[d] * unit(random) : (removed ? n_cells[d] - 1 : 3 + 4 * unit(random));
            position[d].push_back(origin[d] + h * cells);
          }
        material.push_back(removed ? -1 : 0);
      }
    mpm::PointsView<dim, double> p{};
    p.n_points = static_cast<int>(material.size());
    for (int d = 0; d < dim; ++d)
      p.position[d] = position[d].data();
    p.material = material.data();

    std::vector<long>       home;
    const mpm::ActiveNodes  nodes = mpm::nodes_near_points<dim>(origin, h, n_cells, block, p, &home);
    const std::string       where = std::to_string(dim) + "D, blocks of " + std::to_string(block);
    long n_lattice_nodes = 1;
    for (int d = 0; d < dim; ++d)
      n_lattice_nodes *= n_cells[d] + 1;
    check(static_cast<long>(nodes.lattice_to_node.size()) == n_lattice_nodes, ("lookup size, " + where).c_str());
    bool ordered = true;
    for (std::size_t k = 0; k < nodes.lattice_of_node.size(); ++k)
      ordered = ordered && nodes.lattice_to_node[nodes.lattice_of_node[k]] == static_cast<int>(k) &&
                (k == 0 || nodes.lattice_of_node[k] > nodes.lattice_of_node[k - 1]);
    long n_active = 0;
    for (const int node : nodes.lattice_to_node)
      n_active += node >= 0;
    check(ordered && n_active == static_cast<long>(nodes.lattice_of_node.size()),
          ("lattice order, lookup and inverse, " + where).c_str());

    // Home cells, and the cells of the live points in lattice coordinates.
    std::vector<std::array<int, 3>> live_cells;
    bool homes_right = true;
    for (int i = 0; i < p.n_points; ++i)
      {
        double x[dim];
        for (int d = 0; d < dim; ++d)
          x[d] = position[d][i];
        homes_right = homes_right && home[i] == mpm::lattice_cell_containing<dim>(origin, h, n_cells, x);
        if (material[i] < 0)
          continue;
        std::array<int, 3> c{};
        long               rest = home[i];
        for (int d = 0; d < dim; ++d)
          {
            c[d] = static_cast<int>(rest % n_cells[d]);
            rest /= n_cells[d];
          }
        live_cells.push_back(c);
      }
    check(homes_right, ("home cells, " + where).c_str());

    // Not more: every active node within 2B cells of a live point's cell.
    bool near = true;
    for (const long l : nodes.lattice_of_node)
      {
        int  idx[3];
        long rest = l;
        for (int d = 0; d < dim; ++d)
          {
            idx[d] = static_cast<int>(rest % (n_cells[d] + 1));
            rest /= n_cells[d] + 1;
          }
        bool found = false;
        for (const auto &c : live_cells)
          {
            bool inside = true;
            for (int d = 0; d < dim; ++d)
              inside = inside && idx[d] >= c[d] - 2 * block + 1 && idx[d] <= c[d] + 2 * block;
            found = found || inside;
          }
        near = near && found;
      }
    check(near, ("every active node within 2B cells of a point's cell, " + where).c_str());

    // Enough: points anywhere within the margin of their cell, each shape (the extremes of
    // the interval included), clamped into the lattice as points that stay in the grid are.
    const mpm::ShapeFunction shapes[] = {mpm::ShapeFunction::linear, mpm::ShapeFunction::gimp,
                                         mpm::ShapeFunction::bspline2, mpm::ShapeFunction::bspline3};
    for (const mpm::ShapeFunction shape : shapes)
      {
        const double margin = mpm::active_node_margin(shape, block);
        bool         all    = true;
        for (const auto &c : live_cells)
          for (int trial = 0; trial < 40; ++trial)
            {
              double s[3];
              for (int d = 0; d < dim; ++d)
                {
                  const double lower = c[d] - margin, upper = c[d] + 1 + margin;
                  s[d] = trial == 0 ? lower : trial == 1 ? upper - 1e-12 : lower + (upper - lower) * unit(random);
                  s[d] = std::min(std::max(s[d], 0.0), n_cells[d] - 1e-9);
                }
              if (shape == mpm::ShapeFunction::linear)
                all = all && stencil_active<mpm::LinearShape>(s, dim, n_cells, nodes.lattice_to_node);
              else if (shape == mpm::ShapeFunction::gimp)
                all = all && stencil_active<mpm::GimpShape>(s, dim, n_cells, nodes.lattice_to_node);
              else if (shape == mpm::ShapeFunction::bspline2)
                all = all && stencil_active<mpm::QuadraticBSplineShape>(s, dim, n_cells, nodes.lattice_to_node);
              else
                all = all && stencil_active<mpm::CubicBSplineShape>(s, dim, n_cells, nodes.lattice_to_node);
            }
        check(all, ("every stencil node active within the margin (shape " + std::to_string(int(shape)) + "), " +
                    where).c_str());
      }
    std::printf("%s: %ld of %ld nodes active\n", where.c_str(), n_active, n_lattice_nodes);
  }
} // namespace

int main()
{
  std::mt19937 random(7);
  for (int block = 1; block <= 5; ++block)
    {
      check_lattice<2>(block, random);
      check_lattice<3>(block, random);
    }
  return mpm_test::failures() == 0 ? 0 : 1;
}
