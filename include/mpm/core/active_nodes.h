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

  // The active nodes for the points p (those not removed), blocks of block_cells^dim cells.
  // home_cells, where given, receives every point's lattice cell (as GridView::lattice_cell).
  template <int dim, typename Real>
  ActiveNodes nodes_near_points(const Real origin[dim], const Real h, const int n_cells[dim], const int block_cells,
                                const PointsView<dim, Real> &p, std::vector<long> *home_cells = nullptr)
  {
    int  n_blocks[dim];
    long total_blocks = 1;
    for (int d = 0; d < dim; ++d)
      {
        n_blocks[d] = (n_cells[d] + block_cells - 1) / block_cells;
        total_blocks *= n_blocks[d];
      }
    // Blocks holding a point's cell.
    std::vector<std::uint8_t> active(total_blocks, 0);
    if (home_cells != nullptr)
      home_cells->assign(p.n_points, 0);
    for (int i = 0; i < p.n_points; ++i)
      {
        Real x[dim];
        for (int d = 0; d < dim; ++d)
          x[d] = p.position[d][i];
        long cell = lattice_cell_containing<dim>(origin, h, n_cells, x);
        if (home_cells != nullptr)
          (*home_cells)[i] = cell;
        if (p.material[i] < 0)
          continue;
        long block = 0, stride = 1;
        for (int d = 0; d < dim; ++d)
          {
            block += (cell % n_cells[d]) / block_cells * stride;
            cell /= n_cells[d];
            stride *= n_blocks[d];
          }
        active[block] = 1;
      }
    // Their neighbours: the mask dilated by one block along each axis in turn.
    long stride = 1;
    for (int d = 0; d < dim; ++d)
      {
        std::vector<std::uint8_t> grown(active);
        for (long b = 0; b < total_blocks; ++b)
          {
            const long i = b / stride % n_blocks[d];
            if (i > 0 && active[b - stride])
              grown[b] = 1;
            if (i + 1 < n_blocks[d] && active[b + stride])
              grown[b] = 1;
          }
        active.swap(grown);
        stride *= n_blocks[d];
      }
    // A node is active where one of its cells is: node i along an axis touches cells i - 1
    // and i (those inside the lattice), which lie in blocks first_block[i] .. last_block[i].
    std::vector<int> first_block[dim], last_block[dim];
    long             n_lattice_nodes = 1;
    for (int d = 0; d < dim; ++d)
      {
        first_block[d].resize(n_cells[d] + 1);
        last_block[d].resize(n_cells[d] + 1);
        for (int i = 0; i <= n_cells[d]; ++i)
          {
            first_block[d][i] = (i > 0 ? i - 1 : 0) / block_cells;
            last_block[d][i]  = (i < n_cells[d] ? i : n_cells[d] - 1) / block_cells;
          }
        n_lattice_nodes *= n_cells[d] + 1;
      }
    ActiveNodes nodes;
    nodes.lattice_to_node.assign(n_lattice_nodes, -1);
    int idx[dim] = {};
    for (long l = 0; l < n_lattice_nodes; ++l)
      {
        bool is_active = false;
        for (int corner = 0; corner < (1 << dim) && !is_active; ++corner)
          {
            long block = 0, block_stride = 1;
            for (int d = 0; d < dim; ++d)
              {
                block += ((corner >> d) & 1 ? last_block[d][idx[d]] : first_block[d][idx[d]]) * block_stride;
                block_stride *= n_blocks[d];
              }
            is_active = active[block] != 0;
          }
        if (is_active)
          {
            nodes.lattice_to_node[l] = static_cast<int>(nodes.lattice_of_node.size());
            nodes.lattice_of_node.push_back(l);
          }
        for (int d = 0; d < dim && ++idx[d] > n_cells[d]; ++d) // the next lattice node
          idx[d] = 0;
      }
    return nodes;
  }
} // namespace mpm
