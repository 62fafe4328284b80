// Nodes numbered as a box of the lattice with no lookup (GridView's box: the device grids,
// the GPU's nodes near the material) and through a block table (the nodes near the
// material, active_nodes.h), against the whole lattice:
// - box_of_kept_blocks: the box holds every kept block's nodes and no more than the blocks'
//   extent; it is called compact exactly when its blocks are at most
//   box_blocks_per_kept_block times the kept ones; lattice_of_box_nodes is in lattice order;
// - a step on the box's nodes, and one on the nodes of a block table, gives the points of a
//   step on the whole lattice bit for bit:
//   GIMP, the quadratic B-spline (whose folding at the lattice's faces must see the lattice,
//   not the box) and linear shapes, MUSL with pressure averaging (its cell sums at the box's
//   nodes) and USL, a no-slip patch of the floor that the box touches, 2D and 3D, ten steps
//   under gravity.
// The box's lower corner one node off makes every case differ (tried); so does a block
// table whose kept blocks miss the points' neighbourhood by one block.
#include <mpm/core/active_nodes.h>
#include <mpm/core/backend/cpu_backend.h>
#include <mpm/core/host_storage.h>
#include <mpm/core/step.h>

#include "check.h"
#include "scene_helpers.h"

#include <cmath>
#include <random>
#include <string>
#include <vector>

namespace
{
  using namespace mpm;
  using mpm_test::check;

  template <int dim>
  void check_box_of_blocks(std::mt19937 &random)
  {
    const int n_cells[3] = {23, 17, 11}, block = 3;
    long      n_blocks_total = n_blocks<dim>(n_cells, block);
    for (int trial = 0; trial < 50; ++trial)
      {
        // A few random blocks holding points: near one another or far apart.
        std::vector<long>                   holding;
        std::uniform_int_distribution<long> pick(0, n_blocks_total - 1);
        const int                           n_holding = 1 + trial % 4;
        for (int k = 0; k < n_holding; ++k)
          holding.push_back(pick(random));
        NodeBlockChooser<dim> chooser(n_cells, block);
        chooser.choose(holding);
        const std::vector<long> &kept_list = chooser.kept_blocks();
        std::vector<std::uint8_t> kept(n_blocks_total, 0);
        for (const long b : kept_list)
          kept[b] = 1;
        NodeBox<dim> box;
        const bool   compact = box_of_kept_blocks<dim>(n_cells, block, kept_list, box);
        // The box is the bounding box of the kept blocks' cells' vertices.
        long lo[dim], hi[dim], n_kept = 0, n_box_blocks = 1;
        for (int d = 0; d < dim; ++d)
          lo[d] = 1 << 20, hi[d] = -1;
        for (long b = 0; b < n_blocks_total; ++b)
          if (kept[b])
            {
              long rest = b;
              for (int d = 0; d < dim; ++d)
                {
                  const long c = rest % n_blocks_along<dim>(n_cells[d], block);
                  rest /= n_blocks_along<dim>(n_cells[d], block);
                  lo[d] = std::min(lo[d], c * block);
                  hi[d] = std::max(hi[d], std::min((c + 1) * block, long(n_cells[d])));
                }
            }
        bool same = true;
        for (int d = 0; d < dim; ++d)
          same = same && box.lower[d] == lo[d] && box.lower[d] + box.nodes[d] - 1 == hi[d];
        check(same, "the box is the kept nodes' bounding box");
        long box_blocks_lo[dim], box_blocks_hi[dim];
        for (int d = 0; d < dim; ++d)
          box_blocks_lo[d] = 1 << 20, box_blocks_hi[d] = -1;
        for (long b = 0; b < n_blocks_total; ++b)
          if (kept[b])
            {
              ++n_kept;
              long rest = b;
              for (int d = 0; d < dim; ++d)
                {
                  const long n_along = n_blocks_along<dim>(n_cells[d], block);
                  box_blocks_lo[d]   = std::min(box_blocks_lo[d], rest % n_along);
                  box_blocks_hi[d]   = std::max(box_blocks_hi[d], rest % n_along);
                  rest /= n_along;
                }
            }
        for (int d = 0; d < dim; ++d)
          n_box_blocks *= box_blocks_hi[d] - box_blocks_lo[d] + 1;
        check(compact == (n_box_blocks <= box_blocks_per_kept_block * n_kept), "compact as the rule says");
        // The box's own numbering: lattice order, GridView's box and the inverse agreeing.
        const std::vector<long> in_box = lattice_of_box_nodes<dim>(n_cells, box);
        GridView<dim, double>   view{};
        for (int d = 0; d < dim; ++d)
          {
            view.n_cells[d]   = n_cells[d];
            view.box_lower[d] = box.lower[d];
            view.box_nodes[d] = box.nodes[d];
          }
        view.lattice_to_node = nullptr;
        bool ordered         = static_cast<long>(in_box.size()) == box.size();
        for (long b = 0; b < box.size() && ordered; ++b)
          ordered = (b == 0 || in_box[b] > in_box[b - 1]) && view.node_of_lattice(in_box[b]) == b;
        check(ordered, "the box numbered in lattice order");
      }
  }

  // The points after `steps` steps on a grid numbered by `box` or by `blocks` (neither: the
  // whole lattice through its lookup).
  template <int dim, typename Shape>
  HostPoints<dim, double> run(const HostGrid<dim, double> &lattice, HostPoints<dim, double> p, const NodeBox<dim> *box,
                              const NodeBlocks<dim> *blocks, const StepSettings<dim, double> &s)
  {
    HostGrid<dim, double> g = lattice;
    if (box != nullptr || blocks != nullptr)
      {
        const std::vector<long> lattice_of_node =
          box != nullptr ? lattice_of_box_nodes<dim>(lattice.n_cells, *box) : blocks->lattice_of_node;
        const long n_nodes = static_cast<long>(lattice_of_node.size());
        g.allocate_nodes(static_cast<int>(n_nodes));
        for (long b = 0; b < n_nodes; ++b)
          g.fixed_components[b] = lattice_of_node[b] < 0 ? 0 : lattice.fixed_components[lattice_of_node[b]];
        g.lattice_to_node.clear();
        if (blocks != nullptr)
          {
            g.block_slot  = blocks->block_slot;
            g.block_cells = blocks->block_cells;
            for (int d = 0; d < dim; ++d)
              g.node_blocks[d] = blocks->node_blocks[d];
          }
        g.cell_volume.assign(n_nodes, 0);
        g.cell_pressure_volume.assign(n_nodes, 0);
      }
    std::vector<MaterialParameters<double>> materials = {mpm_test::elastic(2e5, 0.3)};
    CpuBackend                              backend;
    for (int step = 0; step < 10; ++step)
      {
        GridView<dim, double> v = g.view();
        v.cell_sums_at_nodes    = box != nullptr || blocks != nullptr;
        if (box != nullptr)
          {
            v.lattice_to_node    = nullptr;
            for (int d = 0; d < dim; ++d)
              {
                v.box_lower[d] = box->lower[d];
                v.box_nodes[d] = box->nodes[d];
              }
          }
        explicit_step<dim, Shape>(backend, v, p.view(), materials.data(), s, 2e-4);
      }
    return p;
  }

  template <int dim, typename Shape>
  void check_step(const char *shape, const UpdateScheme scheme, std::mt19937 &random)
  {
    // A lattice of 20 x 16 (x 12) cells, a no-slip patch on the floor under part of the points
    // (so that a node numbered wrongly gets the wrong mask); points in a block on the floor.
    HostGrid<dim, double> lattice;
    const double          lower[3] = {0, 0, 0};
    const int             cells[3] = {20, 16, 12};
    const double          h        = 0.1;
    lattice.make_dense(lower, h, cells);
    long n_lattice_nodes = static_cast<long>(lattice.mass.size());
    lattice.fixed_components.assign(n_lattice_nodes, 0);
    for (long l = 0; l < n_lattice_nodes; ++l)
      if ((l / (cells[0] + 1)) % (cells[1] + 1) == 0 && l % (cells[0] + 1) <= 9) // y = 0, x <= 0.9 m
        lattice.fixed_components[l] = (1u << dim) - 1;
    HostPoints<dim, double>                 p;
    std::uniform_real_distribution<double> u(0.0, 1.0);
    const int                               n = 300;
    mpm_test::random_points<dim>(p, lattice, n, random);
    for (int i = 0; i < n; ++i)
      {
        p.position[0][i] = h * (7 + 5 * u(random));
        p.position[1][i] = h * (0.3 + 4 * u(random));
        if (dim == 3)
          p.position[dim - 1][i] = h * (4 + 3 * u(random));
        for (int d = 0; d < dim; ++d)
          p.velocity[d][i] *= 0.1;
      }
    auto s = mpm_test::quiet_settings<dim>(scheme);
    s.gravity[1]         = -9.81;
    s.pressure_averaging = scheme == UpdateScheme::musl;
    // The box: lattice nodes x 4..16, y 0..8 (the floor), z 2..10.
    NodeBox<dim> box;
    const int    box_lower[3] = {4, 0, 2}, box_upper[3] = {16, 8, 10};
    for (int d = 0; d < dim; ++d)
      {
        box.lower[d] = box_lower[d];
        box.nodes[d] = box_upper[d] - box_lower[d] + 1;
      }
    // The block table: blocks of 3 cells near the points as they start (the points move
    // less than a cell in the ten steps, within the margin).
    const NodeBlocks<dim> blocks =
      nodes_near_points<dim>(lattice.origin, h, lattice.n_cells, 3, HostPoints<dim, double>(p).view());
    const HostPoints<dim, double> whole  = run<dim, Shape>(lattice, p, nullptr, nullptr, s);
    const HostPoints<dim, double> boxed  = run<dim, Shape>(lattice, p, &box, nullptr, s);
    const HostPoints<dim, double> tabled = run<dim, Shape>(lattice, p, nullptr, &blocks, s);
    auto same = [&](const HostPoints<dim, double> &other) {
      bool identical = true;
      for (int i = 0; i < n; ++i)
        {
          for (int d = 0; d < dim; ++d)
            identical = identical && whole.position[d][i] == other.position[d][i] &&
                        whole.velocity[d][i] == other.velocity[d][i];
          for (int c = 0; c < n_voigt; ++c)
            identical = identical && whole.stress[c][i] == other.stress[c][i];
        }
      return identical;
    };
    double moved = 0;
    for (int i = 0; i < n; ++i)
      for (int d = 0; d < dim; ++d)
        moved = std::max(moved, std::fabs(whole.position[d][i] - p.position[d][i]));
    const bool        box_same = same(boxed), table_same = same(tabled);
    const std::string what = std::to_string(dim) + "D " + shape + (scheme == UpdateScheme::musl ? " MUSL" : " USL");
    std::printf("%s: points moved up to %.3e m in 10 steps; box and lattice %s, block table (%ld nodes) and "
                "lattice %s\n",
                what.c_str(), moved, box_same ? "bit-identical" : "DIFFER", blocks.n_nodes(),
                table_same ? "bit-identical" : "DIFFER");
    check(moved > 1e-5, (what + ": the points moved").c_str());
    check(box_same, (what + ": a step on the box's nodes gives the lattice's points bit for bit").c_str());
    check(table_same, (what + ": a step on a block table's nodes gives the lattice's points bit for bit").c_str());
  }
} // namespace

int main()
{
  std::mt19937 random(11);
  check_box_of_blocks<2>(random);
  check_box_of_blocks<3>(random);
  for (const UpdateScheme scheme : {UpdateScheme::musl, UpdateScheme::usl})
    {
      check_step<2, GimpShape>("GIMP", scheme, random);
      check_step<3, GimpShape>("GIMP", scheme, random);
      check_step<2, QuadraticBSplineShape>("quadratic B-spline", scheme, random);
      check_step<3, QuadraticBSplineShape>("quadratic B-spline", scheme, random);
      check_step<2, LinearShape>("linear", scheme, random);
    }
  return mpm_test::failures() == 0 ? 0 : 1;
}
