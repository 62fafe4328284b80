// The nodes a run keeps where only the material's neighbourhood is meshed (Grid/Nodes =
// near material): cost and memory follow the material, not the size of the box.
//
// The lattice's cells are grouped in blocks of B^dim cells. A block is active where a
// point's cell lies in it or in one of its 3^dim - 1 neighbours, so every cell within B
// cells (max-norm) of a point's cell is in an active block. The active nodes are those
// of the node blocks that hold a vertex of an active block's cell, found through a table
// with one entry per block (GridView::set_block_table), so that neither memory nor the
// work of choosing them grows with the lattice. The node numbering does not change a
// node's sums: the points scatter in their own order whatever it is, so a step over the
// active nodes gives the dense grid's results bit for bit as long as
// every point's stencil stays inside them (active_node_margin).
#pragma once

#include <mpm/core/migration.h>
#include <mpm/core/views.h>

#include <algorithm>
#include <cstdint>
#include <limits>
#include <stdexcept>
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

  // Nodes kept through a block table (GridView::set_block_table): node block c (lattice nodes B c .. B c + B - 1 along each axis) -> slot, -1 where not kept;
  // a kept block's nodes are slot B^dim + their offset in it, x fastest.
  template <int dim>
  struct NodeBlocks
  {
    int               block_cells      = 0;
    int               node_blocks[dim] = {};
    std::vector<int>  block_slot;
    std::vector<long> lattice_of_node; // node -> lattice node index; -1: beyond the lattice's last node

    long n_nodes() const { return static_cast<long>(lattice_of_node.size()); }
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

  // Chooses the nodes near the material, again and again, with work and memory that follow
  // the material: from the cell blocks that hold a point (a list, any order, repeats
  // allowed) it keeps those blocks and their 3^dim - 1 neighbours, and the node blocks that
  // hold a vertex of a kept block's cell (cell block c: node blocks c .. c + 1 along each
  // axis; the lattice's last node of a partial block lies in c itself), numbered in block
  // order. Each choice touches only the kept blocks and the previous choice's: the marks
  // per cell block and the block table stay allocated between choices (one byte and one int
  // per block) and are reset entry by entry.
  template <int dim>
  class NodeBlockChooser
  {
  public:
    NodeBlockChooser(const int n_cells_in[dim], const int block_cells)
    {
      long n_cell_blocks = 1, n_node_blocks = 1;
      table.block_cells  = block_cells;
      for (int d = 0; d < dim; ++d)
        {
          n_cells[d]           = n_cells_in[d];
          cell_blocks[d]       = n_blocks_along<dim>(n_cells[d], block_cells);
          table.node_blocks[d] = n_cells[d] / block_cells + 1;
          n_cell_blocks *= cell_blocks[d];
          n_node_blocks *= table.node_blocks[d];
        }
      mark.assign(n_cell_blocks, 0);
      table.block_slot.assign(n_node_blocks, -1);
    }

    void choose(const std::vector<long> &holding)
    {
      for (const long nb : node_blocks) // the previous choice's table entries
        table.block_slot[nb] = -1;
      previous_node_blocks.swap(node_blocks);
      node_blocks.clear();
      kept.clear();
      // Bit 1: a holding block already expanded; bit 0: kept.
      for (const long b : holding)
        {
          if (mark[b] & 2)
            continue;
          int c[dim];
          coordinates(b, cell_blocks, c);
          for (int k = 0; k < n_neighbours; ++k)
            {
              long n  = 0;
              bool in = true;
              for (int d = dim - 1; d >= 0; --d)
                {
                  const long i = c[d] + (k / power(3, d)) % 3 - 1;
                  in           = in && i >= 0 && i < cell_blocks[d];
                  n            = n * cell_blocks[d] + i;
                }
              if (in && !(mark[n] & 1))
                {
                  mark[n] |= 1;
                  kept.push_back(n);
                }
            }
          mark[b] |= 2; // b is its own neighbour: kept, so cleared below
        }
      for (const long b : kept)
        {
          mark[b] = 0;
          int c[dim];
          coordinates(b, cell_blocks, c);
          for (int corner = 0; corner < (1 << dim); ++corner)
            {
              long nb = 0;
              bool in = true;
              for (int d = dim - 1; d >= 0; --d)
                {
                  const long i = c[d] + ((corner >> d) & 1);
                  in           = in && i < table.node_blocks[d];
                  nb           = nb * table.node_blocks[d] + i;
                }
              if (in && table.block_slot[nb] == -1)
                {
                  table.block_slot[nb] = 0; // listed; numbered below
                  node_blocks.push_back(nb);
                }
            }
        }
      std::sort(kept.begin(), kept.end());
      std::sort(node_blocks.begin(), node_blocks.end());
      long block_nodes = 1;
      for (int d = 0; d < dim; ++d)
        block_nodes *= table.block_cells;
      if (static_cast<long>(node_blocks.size()) * block_nodes > std::numeric_limits<int>::max())
        throw std::length_error("NodeBlockChooser: more nodes near the points than an int can count");
      table.lattice_of_node.resize(node_blocks.size() * block_nodes);
      for (std::size_t slot = 0; slot < node_blocks.size(); ++slot)
        {
          table.block_slot[node_blocks[slot]] = static_cast<int>(slot);
          int c[dim];
          coordinates(node_blocks[slot], table.node_blocks, c);
          for (long k = 0; k < block_nodes; ++k)
            {
              long lattice = 0, stride = 1, r = k;
              bool in      = true;
              for (int d = 0; d < dim; ++d)
                {
                  const long i = c[d] * table.block_cells + r % table.block_cells;
                  r /= table.block_cells;
                  in = in && i <= n_cells[d];
                  lattice += i * stride;
                  stride *= n_cells[d] + 1;
                }
              table.lattice_of_node[slot * block_nodes + k] = in ? lattice : -1;
            }
        }
    }

    // The table and the lattice index of every kept node (-1: beyond the lattice).
    const NodeBlocks<dim> &nodes() const { return table; }
    // The kept cell blocks, in block order.
    const std::vector<long> &kept_blocks() const { return kept; }
    // The kept node blocks in slot order, and those of the choice before.
    const std::vector<long> &kept_node_blocks() const { return node_blocks; }
    const std::vector<long> &previous_kept_node_blocks() const { return previous_node_blocks; }

  private:
    static constexpr int n_neighbours = dim == 2 ? 9 : 27;
    static int           power(const int base, const int e) { return e == 0 ? 1 : base * power(base, e - 1); }
    template <typename Count>
    static void coordinates(long b, const Count along[dim], int c[dim])
    {
      for (int d = 0; d < dim; ++d)
        {
          c[d] = static_cast<int>(b % along[d]);
          b /= along[d];
        }
    }

    int                       n_cells[dim];
    long                      cell_blocks[dim];
    std::vector<std::uint8_t> mark;
    NodeBlocks<dim>           table;
    std::vector<long>         kept, node_blocks, previous_node_blocks;
  };

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

  // The box of the vertices of the kept blocks' cells (a list of cell blocks), and whether
  // it is compact enough to number the nodes by (box_blocks_per_kept_block). No block kept:
  // an empty box.
  template <int dim>
  bool box_of_kept_blocks(const int n_cells[dim], const int block_cells, const std::vector<long> &kept,
                          NodeBox<dim> &box)
  {
    long n_block[dim], lo[dim], hi[dim];
    for (int d = 0; d < dim; ++d)
      {
        n_block[d] = n_blocks_along<dim>(n_cells[d], block_cells);
        lo[d]      = n_block[d];
        hi[d]      = -1;
      }
    for (const long b : kept)
      {
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
    if (kept.empty())
      return true;
    long n_box_blocks = 1;
    for (int d = 0; d < dim; ++d)
      {
        const long upper = (hi[d] + 1) * block_cells < n_cells[d] ? (hi[d] + 1) * block_cells : n_cells[d];
        box.lower[d]     = static_cast<int>(lo[d] * block_cells);
        box.nodes[d]     = static_cast<int>(upper - box.lower[d] + 1);
        n_box_blocks *= hi[d] - lo[d] + 1;
      }
    return n_box_blocks <= box_blocks_per_kept_block * static_cast<long>(kept.size());
  }

  // The lattice index of each of a box's nodes (output, tests).
  template <int dim>
  std::vector<long> lattice_of_box_nodes(const int n_cells[dim], const NodeBox<dim> &box)
  {
    std::vector<long> lattice_of_node(box.size());
    for (long b = 0; b < box.size(); ++b)
      lattice_of_node[b] = box.lattice_of(b, n_cells);
    return lattice_of_node;
  }

  // The cell blocks holding the points p (those not removed), each once per run of equal
  // blocks. home_cells, where given, receives every point's lattice cell (as
  // GridView::lattice_cell).
  template <int dim, typename Real>
  std::vector<long> blocks_holding_points(const Real origin[dim], const Real h, const int n_cells[dim],
                                          const int block_cells, const PointsView<dim, Real> &p,
                                          std::vector<long> *home_cells = nullptr)
  {
    std::vector<long> holding;
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
        const long block = block_of_cell<dim>(cell, n_cells, block_cells);
        if (p.material[i] >= 0 && (holding.empty() || holding.back() != block))
          holding.push_back(block);
      }
    return holding;
  }

  // The nodes near the points p chosen once (tests; a run keeps its NodeBlockChooser).
  template <int dim, typename Real>
  NodeBlocks<dim> nodes_near_points(const Real origin[dim], const Real h, const int n_cells[dim], const int block_cells,
                                    const PointsView<dim, Real> &p, std::vector<long> *home_cells = nullptr)
  {
    NodeBlockChooser<dim> chooser(n_cells, block_cells);
    chooser.choose(blocks_holding_points<dim>(origin, h, n_cells, block_cells, p, home_cells));
    return chooser.nodes();
  }
} // namespace mpm
