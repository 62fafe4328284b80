// The nodes each rank keeps, their numbering and the exchange between ranks (BackgroundGrid::
// distribute_nodes, background_grid.h).
#include <mpm/dealii/background_grid.h>
#include <mpm/core/active_nodes.h>

#include "lattice_box.h"

#include <deal.II/base/partitioner.templates.h>
#include <deal.II/base/quadrature_lib.h>
#include <deal.II/base/utilities.h>
#include <deal.II/dofs/dof_tools.h>
#include <deal.II/grid/grid_generator.h>

#include <algorithm>
#include <cmath>
#include <limits>

namespace mpm
{
  using namespace grid_detail;

  template <int dim>
  void BackgroundGrid<dim>::distribute_nodes()
  {
    long lattice_cells[dim];
    cell_extent<dim>(n_cells, lattice_cells);
    const int k  = cells_per_grid_cell;
    const int kd = lattice_cells_per_grid_cell;

    dof_handler.distribute_dofs(fe);
    locally_owned_dofs = dof_handler.locally_owned_dofs();

    // The lattice cells: 1 in an owned fine deal.II cell, 2 in the one layer around those
    // (corners included; for k = 1 p4est's ghost cells), 0 elsewhere; kept over the box of
    // the owned fine cells and that layer.
    LatticeBox<dim> state_box;
    for (const auto &cell : triangulation.active_cell_iterators())
      if (cell->is_locally_owned() && is_fine(cell))
        for_each_lattice_cell(cell, [&](const long c) { state_box.add(c, lattice_cells); });
    state_box.grow(1, lattice_cells);
    std::vector<std::uint8_t> cell_states(state_box.size(), 0);
    auto                      cell_state = [&](const long c) -> std::uint8_t {
      const long in_box = state_box.index(c, lattice_cells);
      return in_box < 0 ? 0 : cell_states[in_box];
    };
    auto set_cell_state = [&](const long c, const std::uint8_t state) {
      const long in_box = state_box.index(c, lattice_cells);
      AssertThrow(in_box >= 0, dealii::ExcInternalError()); // the box holds the owned cells and their layer
      cell_states[in_box] = state;
    };
    for (const auto &cell : triangulation.active_cell_iterators())
      if (cell->is_locally_owned() && is_fine(cell))
        for_each_lattice_cell(cell, [&](const long c) { set_cell_state(c, 1); });
    auto cell_coordinates = [&](long index, long idx[dim]) { LatticeBox<dim>::coordinates(index, lattice_cells, idx); };
    // Some lattice cell among the 3^dim around cell `idx` (offset -1..1) or the 2^dim around
    // node `idx` (offset -1..0) that is owned (only_owned) or owned or in the layer.
    auto any_around = [&](const long idx[dim], const bool of_node, const bool only_owned) {
      const int lowest = -1, highest = of_node ? 0 : 1, width = highest - lowest + 1;
      for (int j = 0; j < dealii::Utilities::pow(width, dim); ++j)
        {
          long index = 0;
          bool in    = true;
          for (int d = dim - 1, rest = j; d >= 0; --d)
            {
              const int  step = dealii::Utilities::pow(width, d);
              const long i    = idx[d] + lowest + rest / step;
              rest %= step;
              in    = in && i >= 0 && i < n_cells[d];
              index = index * n_cells[d] + (in ? i : 0);
            }
          if (in && (only_owned ? cell_state(index) == 1 : cell_state(index) != 0))
            return true;
        }
      return false;
    };
    for (const auto &cell : triangulation.active_cell_iterators())
      if (cell->is_ghost() && is_fine(cell))
        for_each_lattice_cell(cell, [&](const long c) {
          long idx[dim];
          cell_coordinates(c, idx);
          if (any_around(idx, false, true)) // not the cells of the layer marked so far
            set_cell_state(c, 2);
        });

    // The locally relevant nodes: every DoF of an owned cell, and those of the ghost cells
    // that are a vertex of a lattice cell in the layer (for k = 1 all of them: deal.II's
    // locally relevant DoFs). A DoF's lattice node is its support point's.
    const std::vector<dealii::Point<dim>>        &unit = fe.get_unit_support_points();
    std::vector<dealii::types::global_dof_index> dofs(fe.n_dofs_per_cell());
    // Calls f(DoF, lattice node coordinates) for each relevant DoF of non-artificial cell `cell`.
    auto for_each_relevant_dof = [&](const auto &cell, const auto &f) {
      cell->get_dof_indices(dofs);
      long first[dim];
      lower_lattice_corner(cell, first);
      for (unsigned int i = 0; i < dofs.size(); ++i)
        {
          long idx[dim];
          for (int d = 0; d < dim; ++d)
            idx[d] = first[d] + std::lround(unit[i][d] * k);
          if (k == 1 || cell->is_locally_owned() || any_around(idx, true, false))
            f(dofs[i], idx);
        }
    };
    if (k == 1)
      dealii::DoFTools::extract_locally_relevant_dofs(dof_handler, locally_relevant_dofs);
    else
      {
        dealii::DoFTools::extract_locally_active_dofs(dof_handler, locally_relevant_dofs); // the owned cells'
        std::vector<dealii::types::global_dof_index> layer;
        for (const auto &cell : dof_handler.active_cell_iterators())
          if (cell->is_ghost() && is_fine(cell))
            for_each_relevant_dof(cell, [&](const auto dof, const long *) { layer.push_back(dof); });
        std::sort(layer.begin(), layer.end());
        layer.erase(std::unique(layer.begin(), layer.end()), layer.end());
        locally_relevant_dofs.add_indices(layer.begin(), layer.end());
      }
    partitioner = std::make_shared<dealii::Utilities::MPI::Partitioner>(locally_owned_dofs, locally_relevant_dofs,
                                                                       communicator);
    mass.reinit(partitioner);
    for (unsigned int d = 0; d < dim; ++d)
      {
        momentum[d].reinit(partitioner);
        force[d].reinit(partitioner);
        velocity[d].reinit(partitioner);
      }

    const unsigned int n_local_nodes = partitioner->locally_owned_size() + partitioner->n_ghost_indices();
    // The lookup over the box of the rank's nodes (a coarse cell's DoFs are no lattice nodes).
    LatticeBox<dim> node_box;
    for (const auto &cell : dof_handler.active_cell_iterators())
      if (!cell->is_artificial() && is_fine(cell))
        for_each_relevant_dof(cell, [&](const auto, const long *idx) { node_box.add_at(idx); });
    auto node_map = std::make_shared<LatticeNodeMap<dim>>();
    for (unsigned int d = 0; d < dim; ++d)
      {
        node_map->lower[d] = node_box.along(d) > 0 ? static_cast<int>(node_box.lower[d]) : 0;
        node_map->nodes[d] = static_cast<int>(node_box.along(d));
      }
    node_map->local.assign(node_box.size(), -1);
    for (const auto &cell : dof_handler.active_cell_iterators())
      if (!cell->is_artificial() && is_fine(cell))
        for_each_relevant_dof(cell, [&](const auto dof, const long *idx) {
          node_map->local[node_box.index_at(idx)] = static_cast<int>(partitioner->global_to_local(dof));
        });
    lattice_to_node = node_map;
    fixed_components.assign(n_local_nodes, 0);
    friction_faces.assign(has_friction_face(boundary) ? n_local_nodes : 0, 0);

    // Boundary masks from the face ids: no-slip fixes every component, free-slip the normal
    // one, friction marks the face in the node's friction mask. Every cell holding a boundary
    // node has a face with that node on that boundary, so ghost nodes get the same masks as
    // on their owner.
    std::vector<dealii::types::global_dof_index> face_dofs(fe.n_dofs_per_face());
    for (const auto &cell : dof_handler.active_cell_iterators())
      {
        if (cell->is_artificial())
          continue;
        for (const unsigned int f : cell->face_indices())
          if (cell->face(f)->at_boundary())
            {
              const unsigned int id   = cell->face(f)->boundary_id();
              const BoundaryType type = boundary[id];
              if (type == BoundaryType::free)
                continue;
              const std::uint8_t bits = type == BoundaryType::no_slip ? std::uint8_t((1u << dim) - 1) :
                                        type == BoundaryType::free_slip ? std::uint8_t(1u << (id / 2)) :
                                                                          std::uint8_t(0);
              cell->face(f)->get_dof_indices(face_dofs);
              for (const auto dof : face_dofs)
                if (locally_relevant_dofs.is_element(dof))
                  {
                    const auto node = partitioner->global_to_local(dof);
                    fixed_components[node] |= bits;
                    if (type == BoundaryType::friction)
                      friction_faces[node] |= std::uint8_t(1u << id);
                  }
            }
      }

    // The partitioner of the lattice cells for the per-cell sums of the pressure averaging:
    // lattice cell s of deal.II cell c is (global active cell index of c) x k^dim + s. The
    // owned deal.II cells' global indices are one range on each rank, so are their lattice
    // cells'.
    dealii::types::global_cell_index first_owned = std::numeric_limits<dealii::types::global_cell_index>::max(),
                                     n_owned     = 0;
    std::vector<dealii::types::global_cell_index> ghost_cells;
    for (const auto &cell : triangulation.active_cell_iterators())
      if (cell->is_locally_owned())
        {
          first_owned = std::min(first_owned, cell->global_active_cell_index());
          ++n_owned;
        }
      else if (cell->is_ghost() && is_fine(cell))
        {
          int s = 0;
          for_each_lattice_cell(cell, [&](const long c) {
            if (cell_state(c) == 2)
              ghost_cells.push_back(cell->global_active_cell_index() * kd + s);
            ++s;
          });
        }
    const dealii::types::global_cell_index n_global_cells =
      dealii::Utilities::MPI::sum<dealii::types::global_cell_index>(n_owned, communicator) * kd;
    dealii::IndexSet owned_cells(n_global_cells), ghost_cell_set(n_global_cells);
    if (n_owned > 0)
      owned_cells.add_range(first_owned * kd, (first_owned + n_owned) * kd);
    std::sort(ghost_cells.begin(), ghost_cells.end());
    ghost_cell_set.add_indices(ghost_cells.begin(), ghost_cells.end());
    auto cells = std::make_shared<dealii::Utilities::MPI::Partitioner>(owned_cells, ghost_cell_set, communicator);
    lattice_cell_of_local_cell_index.assign(cells->locally_owned_size() + cells->n_ghost_indices(), -1);
    for (const auto &cell : triangulation.active_cell_iterators())
      if (cell->is_locally_owned() || (cell->is_ghost() && is_fine(cell)))
        {
          AssertThrow(!cell->is_locally_owned() || cell->global_active_cell_index() - first_owned < n_owned,
                      dealii::ExcInternalError()); // the owned cells' indices are one range
          if (!is_fine(cell)) // a coarse owned cell's entries stay -1: no lattice cell
            continue;
          int s = 0;
          for_each_lattice_cell(cell, [&](const long c) {
            const dealii::types::global_cell_index global = cell->global_active_cell_index() * kd + s++;
            if (cell_state(c) != 0)
              lattice_cell_of_local_cell_index[cells->global_to_local(global)] = c;
          });
        }
    cell_partitioner = cells;
  }

  template void BackgroundGrid<2>::distribute_nodes();
  template void BackgroundGrid<3>::distribute_nodes();
} // namespace mpm
