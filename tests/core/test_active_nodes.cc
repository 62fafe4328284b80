// The nodes near the material (active_nodes.h), on lattices whose sizes are not multiples
// of the block, for block sizes 1-5, in 2D and 3D:
// - enough: a point anywhere within active_node_margin cells (max-norm) of the cell it was
//   in finds every node of its stencil active, for each shape function (GIMP at the largest
//   half-length, 1/2; the cubic B-spline GIMP at 1/2 and down to 1e-5), the B-splines'
//   folded ghost nodes included; and a margin 0.1 cell too large finds one missing;
// - not more than the blocks promise: every active node lies in a node block holding a
//   vertex of a cell of a live point's block or its neighbours (2B - 1 cells below the
//   point's cell to 3B - 1 above);
// - the block table and its inverse agree, every node's lattice index once; removed points
//   activate nothing; the home cells are the points' lattice cells;
// - a chooser that chose before gives the same table as a new one (its old entries reset),
//   and keeps exactly the holding blocks and their neighbours.
#include <mpm/core/active_nodes.h>
#include <mpm/core/cubic_bspline_gimp.h>

#include "check.h"

#include <algorithm>
#include <cstdlib>
#include <array>
#include <random>
#include <string>
#include <vector>

namespace
{
  using mpm_test::check;

  // lp: the domain's half-length in cells (GIMP and the cubic B-spline GIMP; the others ignore it).
  template <typename Shape, typename NodeOfLattice>
  bool stencil_active(const double s_all[], const int dim, const int n_cells[], const NodeOfLattice &node_of,
                      const double lp = 0.5)
  {
    int    first[3], n = Shape::n_per_direction;
    double w[3][5], dw[5];
    for (int d = 0; d < dim; ++d)
      Shape::weights_1d(s_all[d], lp, first[d], w[d], dw);
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
        if (nonzero && node_of(lattice) < 0)
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
    const mpm::NodeBlocks<dim> nodes = mpm::nodes_near_points<dim>(origin, h, n_cells, block, p, &home);
    const std::string          where = std::to_string(dim) + "D, blocks of " + std::to_string(block);
    long n_lattice_nodes = 1, n_node_blocks = 1;
    for (int d = 0; d < dim; ++d)
      {
        n_lattice_nodes *= n_cells[d] + 1;
        n_node_blocks *= nodes.node_blocks[d];
      }
    check(static_cast<long>(nodes.block_slot.size()) == n_node_blocks && nodes.block_cells == block,
          ("one table entry per node block, " + where).c_str());
    mpm::GridView<dim, double> view{};
    for (int d = 0; d < dim; ++d)
      view.n_cells[d] = n_cells[d];
    view.set_block_table(nodes.block_slot.data(), nodes.block_cells, nodes.node_blocks);
    auto node_of = [&](const long lattice) { return view.node_of_lattice(lattice); };
    // Every node's lattice index found back through the table, and each lattice node once.
    bool             inverse = true;
    long             n_active = 0;
    std::vector<int> seen(n_lattice_nodes, 0);
    for (std::size_t k = 0; k < nodes.lattice_of_node.size(); ++k)
      if (nodes.lattice_of_node[k] >= 0)
        {
          ++n_active;
          inverse = inverse && node_of(nodes.lattice_of_node[k]) == static_cast<int>(k) &&
                    ++seen[nodes.lattice_of_node[k]] == 1;
        }
    long n_found = 0;
    for (long l = 0; l < n_lattice_nodes; ++l)
      n_found += node_of(l) >= 0;
    check(inverse && n_found == n_active, ("block table and its inverse, " + where).c_str());

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
        if (l < 0) // a node block's node beyond the lattice
          continue;
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
              inside = inside && idx[d] >= c[d] - 2 * block + 1 && idx[d] <= c[d] + 3 * block - 1;
            found = found || inside;
          }
        near = near && found;
      }
    check(near, ("every active node within 2B - 1 below and 3B - 1 above a point's cell, " + where).c_str());

    // Enough: points anywhere within the margin of their cell, each shape (the extremes of
    // the interval included), clamped into the lattice as points that stay in the grid are.
    const mpm::ShapeFunction shapes[] = {mpm::ShapeFunction::linear, mpm::ShapeFunction::gimp,
                                         mpm::ShapeFunction::bspline2, mpm::ShapeFunction::bspline3,
                                         mpm::ShapeFunction::bspline3_gimp};
    for (const mpm::ShapeFunction shape : shapes)
      {
        const double margin = mpm::active_node_margin(shape, block);
        if (margin < 0) // the cubic B-spline GIMP with blocks of 1 cell: refused (Grid/Active block size)
          continue;
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
                all = all && stencil_active<mpm::LinearShape>(s, dim, n_cells, node_of);
              else if (shape == mpm::ShapeFunction::gimp)
                all = all && stencil_active<mpm::GimpShape>(s, dim, n_cells, node_of);
              else if (shape == mpm::ShapeFunction::bspline2)
                all = all && stencil_active<mpm::QuadraticBSplineShape>(s, dim, n_cells, node_of);
              else if (shape == mpm::ShapeFunction::bspline3)
                all = all && stencil_active<mpm::CubicBSplineShape>(s, dim, n_cells, node_of);
              else // its stencil reaches farthest below at lp = 1/2, above at lp -> 0
                for (const double lp : {0.5, 0.25, 1e-3, 1e-5})
                  all = all && stencil_active<mpm::CubicBSplineGimpShape>(s, dim, n_cells, node_of, lp);
            }
        check(all, ("every stencil node active within the margin (shape " + std::to_string(int(shape)) + "), " +
                    where).c_str());
      }
    // Choosing again: from other holding blocks (and repeats), after a first choice.
    {
      const long                          total = mpm::n_blocks<dim>(n_cells, block);
      std::uniform_int_distribution<long> pick(0, total - 1);
      std::vector<long>                   first, second;
      for (int k = 0; k < 6; ++k)
        first.push_back(pick(random));
      for (int k = 0; k < 6; ++k)
        second.push_back(k % 3 == 2 ? second.back() : pick(random));
      mpm::NodeBlockChooser<dim> again(n_cells, block), fresh(n_cells, block);
      again.choose(first);
      again.choose(second);
      fresh.choose(second);
      check(again.nodes().block_slot == fresh.nodes().block_slot &&
              again.nodes().lattice_of_node == fresh.nodes().lattice_of_node &&
              again.kept_blocks() == fresh.kept_blocks(),
            ("a second choice as a first one, " + where).c_str());
      // Exactly the holding blocks' 3^dim neighbourhoods, counted by brute force.
      long n_block[3], expected = 0;
      for (int d = 0; d < dim; ++d)
        n_block[d] = mpm::n_blocks_along<dim>(n_cells[d], block);
      for (long b = 0; b < total; ++b)
        {
          bool near_holding = false;
          for (const long hb : second)
            {
              bool close = true;
              long r1 = b, r2 = hb;
              for (int d = 0; d < dim; ++d)
                {
                  close = close && std::abs(r1 % n_block[d] - r2 % n_block[d]) <= 1;
                  r1 /= n_block[d];
                  r2 /= n_block[d];
                }
              near_holding = near_holding || close;
            }
          expected += near_holding;
        }
      check(static_cast<long>(fresh.kept_blocks().size()) == expected,
            ("the holding blocks and their neighbours kept, " + where).c_str());
    }
    std::printf("%s: %ld of %ld nodes active\n", where.c_str(), n_active, n_lattice_nodes);
  }

  // Not more than needed: a lone point in a cell at the end of its block (the fewest cells
  // kept beyond it on that side), placed 0.1 cell beyond the margin along one axis below or
  // above, finds a node of its stencil with a non-zero weight missing, for each shape at
  // some half-length. So the margin is tight to 0.1 cell on at least one side.
  template <int dim>
  void check_margin_tight(const int block)
  {
    const int    n_cells[3] = {48, 48, 48};
    const double origin[3]  = {0, 0, 0};
    const double h          = 1;
    const mpm::ShapeFunction shapes[] = {mpm::ShapeFunction::linear, mpm::ShapeFunction::gimp,
                                         mpm::ShapeFunction::bspline2, mpm::ShapeFunction::bspline3,
                                         mpm::ShapeFunction::bspline3_gimp};
    for (const mpm::ShapeFunction shape : shapes)
      {
        const double margin = mpm::active_node_margin(shape, block);
        if (margin < 0)
          continue;
        bool missing = false;
        for (const bool above : {false, true})
          {
            // The cell: the last of its block above, the first below; far from the faces.
            const int           c = above ? 4 * block - 1 : 4 * block;
            std::vector<double> position[dim];
            std::vector<int>    material{0};
            for (int d = 0; d < dim; ++d)
              position[d].push_back(c + 0.5);
            mpm::PointsView<dim, double> p{};
            p.n_points = 1;
            for (int d = 0; d < dim; ++d)
              p.position[d] = position[d].data();
            p.material = material.data();
            const mpm::NodeBlocks<dim> nodes = mpm::nodes_near_points<dim>(origin, h, n_cells, block, p, nullptr);
            mpm::GridView<dim, double> view{};
            for (int d = 0; d < dim; ++d)
              view.n_cells[d] = n_cells[d];
            view.set_block_table(nodes.block_slot.data(), nodes.block_cells, nodes.node_blocks);
            auto   node_of = [&](const long lattice) { return view.node_of_lattice(lattice); };
            double s[3]    = {c + 0.5, c + 0.5, c + 0.5};
            s[0]           = above ? c + 1 + margin + 0.1 : c - margin - 0.1;
            for (const double lp : {0.5, 0.25, 1e-3})
              missing = missing ||
                        !(shape == mpm::ShapeFunction::linear ?
                            stencil_active<mpm::LinearShape>(s, dim, n_cells, node_of, lp) :
                          shape == mpm::ShapeFunction::gimp ?
                            stencil_active<mpm::GimpShape>(s, dim, n_cells, node_of, lp) :
                          shape == mpm::ShapeFunction::bspline2 ?
                            stencil_active<mpm::QuadraticBSplineShape>(s, dim, n_cells, node_of, lp) :
                          shape == mpm::ShapeFunction::bspline3 ?
                            stencil_active<mpm::CubicBSplineShape>(s, dim, n_cells, node_of, lp) :
                            stencil_active<mpm::CubicBSplineGimpShape>(s, dim, n_cells, node_of, lp));
          }
        check(missing, ("a node missing 0.1 cell beyond the margin (shape " + std::to_string(int(shape)) + "), " +
                        std::to_string(dim) + "D, blocks of " + std::to_string(block))
                         .c_str());
      }
  }
} // namespace

int main()
{
  std::mt19937 random(7);
  for (int block = 1; block <= 5; ++block)
    {
      check_lattice<2>(block, random);
      check_lattice<3>(block, random);
      check_margin_tight<2>(block);
      check_margin_tight<3>(block);
    }
  return mpm_test::failures() == 0 ? 0 : 1;
}
