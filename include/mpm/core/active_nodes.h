// The nodes a run keeps where only the material's neighbourhood is meshed (Grid/Nodes =
// near material): cost and memory follow the material, not the size of the box.
//
// The lattice's cells are grouped in blocks of B^dim cells. A block is active where a
// point's cell lies in it or in one of its 3^dim - 1 neighbours, so every cell within B
// cells (max-norm) of a point's cell is in an active block. The active nodes are the
// vertices of the active blocks' cells, numbered in lattice order. The node numbering
// does not change a node's sums: the points scatter in their own order whatever it is,
// so a step over the active nodes gives the dense grid's results bit for bit as long as
// every point's stencil stays inside them (active_node_margin).
#pragma once

#include <mpm/core/migration.h>
#include <mpm/core/views.h>

#include <cstdint>
#include <vector>

namespace mpm
{
  // Cells (max-norm) a point may move out of the cell it was in when the active nodes were
  // chosen before its stencil can reach a node that is not active: the shape's own safe
  // distance outside the home cell's ring of nodes (migration.h) plus the B - 1 further
  // rings an active block's neighbours guarantee.
  inline double active_node_margin(const ShapeFunction shape, const int block_cells)
  {
    return safe_distance_outside_home_cell(shape) + (block_cells - 1);
  }

  struct ActiveNodes
  {
    std::vector<int>  lattice_to_node; // lattice node index -> active node, -1 elsewhere
    std::vector<long> lattice_of_node; // active node -> lattice node index
  };

  // Blocks of block_cells^dim cells along each axis of a lattice of n_cells cells.
  template <int dim>
  MPM_HOST_DEVICE inline long n_blocks_along(const int n_cells, const int block_cells)
  {
    return (n_cells + block_cells - 1) / block_cells;
  }

  // The block of lattice cell `cell` (i + n_x (j + n_y k)), numbered the same way over blocks.
  template <int dim>
  MPM_HOST_DEVICE inline long block_of_cell(long cell, const int n_cells[dim], const int block_cells)
  {
    long block = 0, stride = 1;
    for (int d = 0; d < dim; ++d)
      {
        block += (cell % n_cells[d]) / block_cells * stride;
        cell /= n_cells[d];
        stride *= n_blocks_along<dim>(n_cells[d], block_cells);
      }
    return block;
  }

  template <int dim>
  long n_blocks(const int n_cells[dim], const int block_cells)
  {
    long n = 1;
    for (int d = 0; d < dim; ++d)
      n *= n_blocks_along<dim>(n_cells[d], block_cells);
    return n;
  }

  // The blocks kept for the blocks that hold a point's cell (holding[b] != 0, one entry per
  // block): those blocks and their neighbours.
  template <int dim>
  std::vector<std::uint8_t> kept_blocks(const int n_cells[dim], const int block_cells,
                                        std::vector<std::uint8_t> holding)
  {
    long n_block[dim], total_blocks = 1;
    for (int d = 0; d < dim; ++d)
      {
        n_block[d] = n_blocks_along<dim>(n_cells[d], block_cells);
        total_blocks *= n_block[d];
      }
    // The mask dilated by one block along each axis in turn.
    long stride = 1;
    for (int d = 0; d < dim; ++d)
      {
        std::vector<std::uint8_t> grown(holding);
        for (long b = 0; b < total_blocks; ++b)
          {
            const long i = b / stride % n_block[d];
            if ((i > 0 && holding[b - stride]) || (i + 1 < n_block[d] && holding[b + stride]))
              grown[b] = 1;
          }
        holding.swap(grown);
        stride *= n_block[d];
      }
    return holding;
  }

  // The vertices of the kept blocks' cells (kept[b] != 0), numbered in lattice order.
  template <int dim>
  ActiveNodes nodes_of_kept_blocks(const int n_cells[dim], const int block_cells,
                                   const std::vector<std::uint8_t> &kept_block)
  {
    long n_block[dim], total_blocks = 1, n_lattice_nodes = 1, node_stride[dim];
    for (int d = 0; d < dim; ++d)
      {
        n_block[d]     = n_blocks_along<dim>(n_cells[d], block_cells);
        node_stride[d] = n_lattice_nodes;
        total_blocks *= n_block[d];
        n_lattice_nodes *= n_cells[d] + 1;
      }
    // The vertices of a kept block's cells: lattice nodes B b .. B (b + 1) along each axis
    // (clipped to the lattice), marked, then numbered in lattice order.
    std::vector<std::uint8_t> kept(n_lattice_nodes, 0);
    for (long b = 0; b < total_blocks; ++b)
      {
        if (!kept_block[b])
          continue;
        int  lower[dim], upper[dim], idx[dim];
        long rest = b;
        for (int d = 0; d < dim; ++d)
          {
            const int i = static_cast<int>(rest % n_block[d]);
            rest /= n_block[d];
            lower[d] = i * block_cells;
            upper[d] = (i + 1) * block_cells < n_cells[d] ? (i + 1) * block_cells : n_cells[d];
            idx[d]   = lower[d];
          }
        for (bool more = true; more;)
          {
            long lattice = 0;
            for (int d = 0; d < dim; ++d)
              lattice += idx[d] * node_stride[d];
            kept[lattice] = 1;
            more          = false;
            for (int d = 0; d < dim && !more; ++d) // the next node of the block
              if (++idx[d] <= upper[d])
                more = true;
              else
                idx[d] = lower[d];
          }
      }
    ActiveNodes nodes;
    nodes.lattice_to_node.assign(n_lattice_nodes, -1);
    for (long l = 0; l < n_lattice_nodes; ++l)
      if (kept[l])
        {
          nodes.lattice_to_node[l] = static_cast<int>(nodes.lattice_of_node.size());
          nodes.lattice_of_node.push_back(l);
        }
    return nodes;
  }

  // The active nodes from the blocks that hold a point's cell: the vertices of those blocks'
  // and their neighbours' cells.
  template <int dim>
  ActiveNodes nodes_of_blocks(const int n_cells[dim], const int block_cells, std::vector<std::uint8_t> holding)
  {
    return nodes_of_kept_blocks<dim>(n_cells, block_cells, kept_blocks<dim>(n_cells, block_cells, std::move(holding)));
  }

  // A box of lattice nodes: lower[d] .. lower[d] + nodes[d] - 1 along each axis.
  template <int dim>
  struct NodeBox
  {
    int lower[dim] = {};
    int nodes[dim] = {};

    long size() const
    {
      long n = 1;
      for (int d = 0; d < dim; ++d)
        n *= nodes[d];
      return n;
    }

    // Lattice index of the box's node b (x fastest in both).
    long lattice_of(long b, const int n_cells[dim]) const
    {
      long lattice = 0, stride = 1;
      for (int d = 0; d < dim; ++d)
        {
          lattice += (lower[d] + b % nodes[d]) * stride;
          b /= nodes[d];
          stride *= n_cells[d] + 1;
        }
      return lattice;
    }
  };

  // A device grid numbers the kept nodes as the box around them, with no lookup (which cost
  // 4% of P2's step), where that box holds at most this many times the kept blocks: the
  // nodes between the kept blocks cost memory and the grid passes, not point work.
  constexpr long box_blocks_per_kept_block = 2;

  // The box of the vertices of the kept blocks' cells (kept[b] != 0), and whether it is
  // compact enough to number the nodes by (box_blocks_per_kept_block). No block kept: an
  // empty box.
  template <int dim>
  bool box_of_kept_blocks(const int n_cells[dim], const int block_cells, const std::vector<std::uint8_t> &kept,
                          NodeBox<dim> &box)
  {
    long n_block[dim], lo[dim], hi[dim], n_kept = 0;
    for (int d = 0; d < dim; ++d)
      {
        n_block[d] = n_blocks_along<dim>(n_cells[d], block_cells);
        lo[d]      = n_block[d];
        hi[d]      = -1;
      }
    for (long b = 0; b < static_cast<long>(kept.size()); ++b)
      if (kept[b])
        {
          ++n_kept;
          long rest = b;
          for (int d = 0; d < dim; ++d)
            {
              const long i = rest % n_block[d];
              rest /= n_block[d];
              lo[d] = i < lo[d] ? i : lo[d];
              hi[d] = i > hi[d] ? i : hi[d];
            }
        }
    box = NodeBox<dim>();
    if (n_kept == 0)
      return true;
    long n_box_blocks = 1;
    for (int d = 0; d < dim; ++d)
      {
        const long upper = (hi[d] + 1) * block_cells < n_cells[d] ? (hi[d] + 1) * block_cells : n_cells[d];
        box.lower[d]     = static_cast<int>(lo[d] * block_cells);
        box.nodes[d]     = static_cast<int>(upper - box.lower[d] + 1);
        n_box_blocks *= hi[d] - lo[d] + 1;
      }
    return n_box_blocks <= box_blocks_per_kept_block * n_kept;
  }

  // The lookup of a box's nodes and its inverse (output, tests).
  template <int dim>
  ActiveNodes nodes_of_box(const int n_cells[dim], const NodeBox<dim> &box)
  {
    long n_lattice_nodes = 1;
    for (int d = 0; d < dim; ++d)
      n_lattice_nodes *= n_cells[d] + 1;
    ActiveNodes nodes;
    nodes.lattice_to_node.assign(n_lattice_nodes, -1);
    nodes.lattice_of_node.resize(box.size());
    for (long b = 0; b < box.size(); ++b)
      {
        nodes.lattice_of_node[b]                        = box.lattice_of(b, n_cells);
        nodes.lattice_to_node[nodes.lattice_of_node[b]] = static_cast<int>(b);
      }
    return nodes;
  }

  // The active nodes for the points p (those not removed), blocks of block_cells^dim cells.
  // home_cells, where given, receives every point's lattice cell (as GridView::lattice_cell).
  template <int dim, typename Real>
  ActiveNodes nodes_near_points(const Real origin[dim], const Real h, const int n_cells[dim], const int block_cells,
                                const PointsView<dim, Real> &p, std::vector<long> *home_cells = nullptr)
  {
    std::vector<std::uint8_t> holding(n_blocks<dim>(n_cells, block_cells), 0);
    if (home_cells != nullptr)
      home_cells->assign(p.n_points, 0);
    for (int i = 0; i < p.n_points; ++i)
      {
        Real x[dim];
        for (int d = 0; d < dim; ++d)
          x[d] = p.position[d][i];
        const long cell = lattice_cell_containing<dim>(origin, h, n_cells, x);
        if (home_cells != nullptr)
          (*home_cells)[i] = cell;
        if (p.material[i] >= 0)
          holding[block_of_cell<dim>(cell, n_cells, block_cells)] = 1;
      }
    return nodes_of_blocks<dim>(n_cells, block_cells, std::move(holding));
  }
} // namespace mpm
