#include <mpm/dealii/background_grid.h>

#include <deal.II/base/utilities.h>
#include <deal.II/dofs/dof_tools.h>
#include <deal.II/grid/grid_generator.h>

#include <cmath>

namespace mpm
{
  template <int dim>
  BackgroundGrid<dim>::BackgroundGrid(const Parameters &parameters, MPI_Comm communicator)
    : communicator(communicator)
    , triangulation(communicator)
    , fe(1)
    , dof_handler(triangulation)
  {
    h = parameters.cell_size;
    std::vector<unsigned int> repetitions(dim);
    dealii::Point<dim>        p1, p2;
    long                      n_lattice_cells = 1, n_lattice_nodes = 1;
    for (unsigned int d = 0; d < dim; ++d)
      {
        origin[d]      = parameters.lower[d];
        n_cells[d]     = static_cast<int>(std::lround((parameters.upper[d] - parameters.lower[d]) / h));
        repetitions[d] = n_cells[d];
        p1[d]          = parameters.lower[d];
        p2[d]          = parameters.lower[d] + n_cells[d] * h;
        n_lattice_cells *= n_cells[d];
        n_lattice_nodes *= n_cells[d] + 1;
      }
    // colorize: boundary ids 0..2dim-1 for x min, x max, y min, ...
    dealii::GridGenerator::subdivided_hyper_rectangle(triangulation, repetitions, p1, p2, true);
    dof_handler.distribute_dofs(fe);
    locally_owned_dofs = dof_handler.locally_owned_dofs();
    dealii::DoFTools::extract_locally_relevant_dofs(dof_handler, locally_relevant_dofs);
    partitioner = std::make_shared<dealii::Utilities::MPI::Partitioner>(locally_owned_dofs, locally_relevant_dofs,
                                                                       communicator);
    mass.reinit(partitioner);
    for (unsigned int d = 0; d < dim; ++d)
      {
        momentum[d].reinit(partitioner);
        force[d].reinit(partitioner);
        velocity[d].reinit(partitioner);
      }
    vector_of_array[mass.begin()] = &mass;
    for (unsigned int d = 0; d < dim; ++d)
      {
        vector_of_array[momentum[d].begin()] = &momentum[d];
        vector_of_array[force[d].begin()]    = &force[d];
      }

    const unsigned int n_local_nodes = partitioner->locally_owned_size() + partitioner->n_ghost_indices();
    lattice_to_node.assign(n_lattice_nodes, -1);
    fixed_components.assign(n_local_nodes, 0);
    cell_of_lattice_cell.assign(n_lattice_cells, triangulation.end());

    auto lattice_index = [&](const dealii::Point<dim> &x, const bool of_cell) {
      long index = 0;
      for (int d = dim - 1; d >= 0; --d)
        {
          const long i = of_cell ? static_cast<long>(std::floor((x[d] - origin[d]) / h)) :
                                   std::lround((x[d] - origin[d]) / h);
          index = index * (of_cell ? n_cells[d] : n_cells[d] + 1) + i;
        }
      return index;
    };

    for (const auto &cell : dof_handler.active_cell_iterators())
      {
        if (cell->is_artificial())
          continue;
        if (cell->is_locally_owned())
          cell_of_lattice_cell[lattice_index(cell->center(), true)] = cell;
        for (const unsigned int v : cell->vertex_indices())
          {
            const auto global = cell->vertex_dof_index(v, 0);
            lattice_to_node[lattice_index(cell->vertex(v), false)] =
              static_cast<int>(partitioner->global_to_local(global));
          }
        // Boundary masks from the face ids: no-slip fixes every component, free-slip the normal one.
        for (const unsigned int f : cell->face_indices())
          if (cell->face(f)->at_boundary())
            {
              const unsigned int id   = cell->face(f)->boundary_id();
              const BoundaryType type = parameters.boundary[id];
              if (type == BoundaryType::free)
                continue;
              const std::uint8_t bits = type == BoundaryType::no_slip ? std::uint8_t((1u << dim) - 1) :
                                                                       std::uint8_t(1u << (id / 2));
              for (unsigned int fv = 0; fv < dealii::GeometryInfo<dim>::vertices_per_face; ++fv)
                {
                  const auto global = cell->face(f)->vertex_dof_index(fv, 0);
                  fixed_components[partitioner->global_to_local(global)] |= bits;
                }
            }
      }
  }

  template <int dim>
  typename dealii::Triangulation<dim>::active_cell_iterator BackgroundGrid<dim>::owned_cell(const long c) const
  {
    return cell_of_lattice_cell[c];
  }

  template <int dim>
  long BackgroundGrid<dim>::lattice_cell_of(const double *x) const
  {
    long index = 0;
    for (int d = dim - 1; d >= 0; --d)
      {
        long i = static_cast<long>(std::floor((x[d] - origin[d]) / h));
        i      = std::min<long>(std::max<long>(i, 0), n_cells[d] - 1);
        index  = index * n_cells[d] + i;
      }
    return index;
  }

  template <int dim>
  mpm::GridView<dim, double> BackgroundGrid<dim>::view()
  {
    mpm::GridView<dim, double> v;
    for (unsigned int d = 0; d < dim; ++d)
      {
        v.origin[d]   = origin[d];
        v.n_cells[d]  = n_cells[d];
        v.momentum[d] = momentum[d].begin();
        v.force[d]    = force[d].begin();
        v.velocity[d] = velocity[d].begin();
      }
    v.h                = h;
    v.lattice_to_node  = lattice_to_node.data();
    v.n_nodes          = static_cast<int>(fixed_components.size());
    v.mass             = mass.begin();
    v.fixed_components = fixed_components.data();
    return v;
  }

  template <int dim>
  void BackgroundGrid<dim>::sum_nodal(double *const *arrays, const int count) const
  {
    if (dealii::Utilities::MPI::n_mpi_processes(communicator) == 1)
      return;
    for (int i = 0; i < count; ++i)
      {
        Vector *v = vector_of_array.at(arrays[i]);
        v->compress(dealii::VectorOperation::add);
        v->update_ghost_values();
      }
  }

  template class BackgroundGrid<2>;
  template class BackgroundGrid<3>;
} // namespace mpm
