// Plain views (pointers + sizes) of the grid and point arrays the step works on.
// They own nothing: the deal.II layer or a standalone driver allocates the memory
// (host or device) and fills the views. Arrays are structure-of-arrays so that
// consecutive points / nodes are consecutive in memory on every backend.
#pragma once

#include <mpm/core/config.h>
#include <mpm/core/point_fields.h>

#include <cmath>
#include <cstdint>

namespace mpm
{
  // Lattice cell containing x, clamped to the grid: i + n_x (j + n_y k). The one formula
  // for the step, the device's migration kernels and the deal.II layer's lookups, so that
  // a point on a cell face lands in the same cell everywhere.
  template <int dim, typename Real>
  MPM_HOST_DEVICE inline long lattice_cell_containing(const Real origin[dim], const Real h, const int n_cells[dim],
                                                      const Real x[dim])
  {
    long cell = 0;
    for (int d = dim - 1; d >= 0; --d)
      {
        long i = static_cast<long>(std::floor((x[d] - origin[d]) / h));
        i      = i < 0 ? 0 : (i >= n_cells[d] ? n_cells[d] - 1 : i);
        cell   = cell * n_cells[d] + i;
      }
    return cell;
  }

  // Coordinates (i,j,k) of lattice node `lattice` (i + (n_x + 1) (j + (n_y + 1) k)).
  template <int dim>
  MPM_HOST_DEVICE inline void lattice_node_coordinates(const int n_cells[dim], long lattice, int idx[dim])
  {
    for (int d = 0; d < dim; ++d)
      {
        idx[d] = static_cast<int>(lattice % (n_cells[d] + 1));
        lattice /= n_cells[d] + 1;
      }
  }

  // Uniform background lattice. Its nodes are numbered in one of three ways: through a
  // lookup over a box of the lattice (deal.II's locally relevant DoF space: the box around
  // a rank's nodes, so that its memory follows the rank's cells, not the lattice); through
  // a block table, one entry per block of nodes (the nodes near the material,
  // active_nodes.h: memory that follows the material, not the lattice); or, with neither,
  // as a box of the lattice in lattice order (device grids: the whole lattice, a rank's
  // slab, the box around the material), whose index is computed, not looked up.
  template <int dim, typename Real>
  struct GridView
  {
    Real origin[dim];           // lower corner of the grid
    Real h;                     // cell size, equal in every direction
    int  n_cells[dim];          // cells per direction
    // The box of lattice nodes box_lower[d] .. box_lower[d] + box_nodes[d] - 1 along each
    // axis, x fastest; a lattice node outside it is absent. Its index (node_in_box) -> local
    // node index, -1 if absent; with block_cells > 0 the block table instead
    // (set_block_table; no box). Null: the box's index is the local node index. (The box is
    // tested first and the table inside the lookup's branch, so that the dense grids'
    // kernels carry no more than before.)
    const int *lattice_to_node;
    int        n_nodes;             // local nodes (length of the arrays below)
    int        box_lower[dim] = {}; // the box's first lattice node
    int        box_nodes[dim] = {}; // and its nodes along each axis (inside the lattice)
    int        block_cells      = 0;  // > 0: lattice_to_node is a block table of blocks of B nodes per axis
    int        node_blocks[dim] = {}; // its node blocks along each axis

    Real *mass;
    Real *momentum[dim];
    Real *force[dim];    // force; after the grid update, the nodal part of G2P's velocity (update_grid)
    Real *velocity[dim]; // nodal velocity used by G2P kinematics
    const std::uint8_t *fixed_components; // bit d set: velocity component d is prescribed zero
    // Frictional walls (wall_friction.h): bit f set where the node lies on grid face f
    // (x min, x max, y min, ...) and that face's wall is frictional. Null: no such face.
    const std::uint8_t *friction_faces = nullptr;
    Real                friction_coefficient[2 * dim] = {}; // mu of each face

    // Per-cell scratch sums of the optional cell pressure averaging (step.h), one entry
    // per lattice cell, indexed like lattice_cell(). Null where the owner of the grid
    // arrays provides none; the step then refuses pressure averaging.
    Real *cell_volume          = nullptr; // sum of V_p over the points of the cell
    Real *cell_pressure_volume = nullptr; // sum of V_p p_p
    // Where the grid keeps only the nodes near the material (active_nodes.h), a cell's sums
    // sit at its lowest vertex, a node of every cell that can hold a point: the arrays
    // above are then n_nodes long, not one entry per lattice cell.
    bool cell_sums_at_nodes = false;
    // Host backends: the only nodes a point can reach, ascending, and their number (several
    // ranks with the nodes near the material: the rank's arrays hold every node of its fine
    // cells, the node loops visit these). Null: every node. The cell sums must then sit at
    // the nodes.
    const int *node_list = nullptr;
    int        n_listed  = 0;

    MPM_HOST_DEVICE int n_lattice_cells() const
    {
      int n = 1;
      for (int d = 0; d < dim; ++d)
        n *= n_cells[d];
      return n;
    }

    // Lattice cell containing x (clamped to the grid): i + n_x (j + n_y k).
    MPM_HOST_DEVICE int lattice_cell(const Real x[dim]) const
    {
      return static_cast<int>(lattice_cell_containing<dim>(origin, h, n_cells, x));
    }

    MPM_HOST_DEVICE int n_lattice_nodes(const int d) const { return n_cells[d] + 1; }

    // Entry of the pressure averaging's sums for the cell containing x (clamped like
    // lattice_cell): the lattice cell, or its lowest vertex's node (cell_sums_at_nodes; -1
    // where that node is not kept).
    MPM_HOST_DEVICE int cell_sum_entry(const Real x[dim]) const
    {
      if (!cell_sums_at_nodes)
        return lattice_cell(x);
      int idx[dim];
      for (int d = 0; d < dim; ++d)
        {
          const long i = static_cast<long>(std::floor((x[d] - origin[d]) / h));
          idx[d]       = static_cast<int>(i < 0 ? 0 : (i >= n_cells[d] ? n_cells[d] - 1 : i));
        }
      return node(idx);
    }

    // Local node index of lattice node (i,j,k), or -1 outside the lattice or absent.
    MPM_HOST_DEVICE int node(const int idx[dim]) const
    {
      if (lattice_to_node == nullptr)
        return node_in_box(idx);
      if (block_cells > 0)
        return node_in_blocks(idx);
      const int in_box = node_in_box(idx);
      return in_box < 0 ? -1 : lattice_to_node[in_box];
    }

    // The box's index of node (i,j,k) (without a lookup the node itself), -1 outside the box
    // (the box lies inside the lattice, so this covers the lattice's ends too).
    MPM_HOST_DEVICE int node_in_box(const int idx[dim]) const
    {
      long node = 0;
      for (int d = dim - 1; d >= 0; --d)
        {
          // One compare for both ends (a negative difference wraps to a large one).
          const unsigned int i = static_cast<unsigned int>(idx[d] - box_lower[d]);
          if (i >= static_cast<unsigned int>(box_nodes[d]))
            return -1;
          node = node * box_nodes[d] + i;
        }
      return static_cast<int>(node);
    }

    // The nodes through a block table: node block (lattice nodes B c .. B c + B - 1 along
    // each axis, c x fastest over node_blocks) -> slot, -1 where not kept; a kept block's
    // nodes are slot B^dim + their offset in it, x fastest.
    MPM_HOST_DEVICE void set_block_table(const int *slots, const int cells, const int blocks[dim])
    {
      lattice_to_node = slots;
      block_cells     = cells;
      for (int d = 0; d < dim; ++d)
        node_blocks[d] = blocks[d];
    }

    // Through the block table: the node (i,j,k), -1 outside the lattice or not kept.
    MPM_HOST_DEVICE int node_in_blocks(const int idx[dim]) const
    {
      long block = 0;
      int  offset = 0, block_nodes = 1;
      for (int d = dim - 1; d >= 0; --d)
        {
          if (idx[d] < 0 || idx[d] > n_cells[d])
            return -1;
          block  = block * node_blocks[d] + idx[d] / block_cells;
          offset = offset * block_cells + idx[d] % block_cells;
          block_nodes *= block_cells;
        }
      const int slot = lattice_to_node[block];
      return slot < 0 ? -1 : slot * block_nodes + offset;
    }

    // Local node index of a lattice index inside the lattice (-1: absent).
    MPM_HOST_DEVICE int node_of_lattice(const long lattice) const
    {
      int idx[dim];
      lattice_node_coordinates<dim>(n_cells, lattice, idx);
      return node(idx);
    }

    // The node at a box index computed by stencil_base (interpolation.h): through the
    // lookup, or the box's index itself.
    MPM_HOST_DEVICE int node_at(const long index) const
    {
      return lattice_to_node != nullptr ? lattice_to_node[index] : static_cast<int>(index);
    }

    // The box of the whole lattice.
    MPM_HOST_DEVICE void box_is_lattice()
    {
      for (int d = 0; d < dim; ++d)
        {
          box_lower[d] = 0;
          box_nodes[d] = n_cells[d] + 1;
        }
    }
  };

  // Material point arrays: one member per core field of point_fields.h (position[d],
  // mass, stress[c], material, ...; null where the run's points do not carry it).
  // material[p] < 0 marks a point that left the grid.
  template <int dim, typename Real>
  struct PointsView
  {
    template <typename T>
    using FieldArray = T *;

    int n_points = 0;
    MPM_POINT_CORE_MEMBERS
    // State variables of user models (user_model.h) or of the affine transfers: variable k
    // of point i is state_variables[k][i]. None (0) unless the run's models declare some.
    Real *state_variables[max_state_variables] = {};
    int   n_state_variables                     = 0;
  };

  // Points first .. first + count - 1 of p, as a view of their own (point 0 is p's point first).
  template <int dim, typename Real>
  PointsView<dim, Real> point_range(PointsView<dim, Real> p, const int first, const int count)
  {
    p.n_points = count;
    auto shift = [first](auto *&array) {
      if (array != nullptr)
        array += first;
    };
    for_each_core_field(p, [&](PointField, auto &member) { for_each_array_of(member, shift); });
    for (int k = 0; k < p.n_state_variables; ++k)
      shift(p.state_variables[k]);
    return p;
  }
} // namespace mpm
