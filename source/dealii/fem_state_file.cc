#include <mpm/dealii/fem_handover_lattice.h>
#include <mpm/dealii/fem_state_file.h>

#include <deal.II/base/mpi.h>
#include <deal.II/distributed/tria.h>
#include <deal.II/dofs/dof_tools.h>
#include <deal.II/fe/fe_tools.h>
#include <deal.II/grid/grid_tools.h>
#include <deal.II/grid/tria_description.h>
#include <deal.II/lac/la_parallel_vector.h>

#include <boost/archive/binary_iarchive.hpp>
#include <boost/archive/binary_oarchive.hpp>
#include <boost/serialization/string.hpp>
#include <boost/serialization/vector.hpp>

#include <cstdio>
#include <fstream>

namespace mpm
{
  using dealii::ExcMessage;

  void write_fem_state_file(const std::string &filename, const FemStateHeader &header, const FemStateCells &cells,
                            MPI_Comm communicator)
  {
    const std::vector<FemStateCells> all = dealii::Utilities::MPI::gather(communicator, cells, 0);
    bool written = true;
    if (dealii::Utilities::MPI::this_mpi_process(communicator) == 0)
      {
        FemStateCells merged;
        for (const FemStateCells &part : all)
          {
            merged.vertices.insert(merged.vertices.end(), part.vertices.begin(), part.vertices.end());
            merged.material_ids.insert(merged.material_ids.end(), part.material_ids.begin(), part.material_ids.end());
            merged.dof_values.insert(merged.dof_values.end(), part.dof_values.begin(), part.dof_values.end());
            merged.states.insert(merged.states.end(), part.states.begin(), part.states.end());
          }
        // Written beside, then renamed: a reader never sees half a file.
        const std::string partial = filename + ".partial";
        {
          std::ofstream out(partial, std::ios::binary);
          if (out)
            {
              boost::archive::binary_oarchive archive(out);
              archive << header << merged;
            }
          written = static_cast<bool>(out);
        }
        written = written && std::rename(partial.c_str(), filename.c_str()) == 0;
      }
    written = dealii::Utilities::MPI::min(written ? 1 : 0, communicator) == 1;
    AssertThrow(written, ExcMessage("save_fem_state: cannot write the file '" + filename + "'."));
  }

  template <int dim>
  std::vector<GeneratedBody<dim>> load_fem_state_points(const Parameters &parameters, MPI_Comm communicator)
  {
    const std::string entry = "Initial state/FEM file";
    const std::string &file = parameters.initial_state.fem_file;
    FemStateHeader     header;
    FemStateCells      cells;
    {
      std::ifstream in(file, std::ios::binary);
      AssertThrow(in, ExcMessage("Parameter '" + entry + "': cannot open '" + file + "'."));
      try
        {
          boost::archive::binary_iarchive archive(in);
          archive >> header >> cells;
        }
      catch (const std::exception &e)
        {
          AssertThrow(false, ExcMessage("Parameter '" + entry + "': '" + file + "' is not an FEM state written by "
                                        "mpm::save_fem_state (" + e.what() + ")."));
        }
    }
    AssertThrow(header.dim == dim, ExcMessage("Parameter '" + entry + "': '" + file + "' holds a " +
                                              std::to_string(header.dim) + "D state, the scene is " +
                                              std::to_string(dim) + "D (Dimension)."));

    // The mesh: the saved cells as the coarse cells of a distributed triangulation.
    constexpr unsigned int n_vertices = dealii::GeometryInfo<dim>::vertices_per_cell;
    const std::size_t      n_cells    = cells.material_ids.size();
    const unsigned int     n_q        = header.quadrature_weights.size();
    AssertThrow(n_cells > 0 && cells.vertices.size() == n_cells * n_vertices * dim &&
                  cells.states.size() == n_cells * n_q * (n_voigt + 1 + header.n_state_variables) &&
                  header.quadrature_points.size() == n_q * dim,
                ExcMessage("Parameter '" + entry + "': '" + file + "' is inconsistent (cell, vertex and state "
                           "counts do not match)."));
    std::vector<dealii::Point<dim>>    vertices(n_cells * n_vertices);
    std::vector<dealii::CellData<dim>> cell_data(n_cells);
    for (std::size_t c = 0; c < n_cells; ++c)
      {
        cell_data[c].vertices.resize(n_vertices);
        for (unsigned int v = 0; v < n_vertices; ++v)
          {
            for (int d = 0; d < dim; ++d)
              vertices[c * n_vertices + v][d] = cells.vertices[(c * n_vertices + v) * dim + d];
            cell_data[c].vertices[v] = c * n_vertices + v;
          }
        cell_data[c].material_id = cells.material_ids[c];
      }
    dealii::SubCellData           no_faces;
    std::vector<unsigned int>     all_vertices;
    dealii::GridTools::delete_duplicated_vertices(vertices, cell_data, no_faces, all_vertices);
    dealii::parallel::distributed::Triangulation<dim> triangulation(communicator);
    triangulation.create_triangulation(vertices, cell_data, no_faces);

    // The FE, the displacement on every cell this rank sees, the quadrature and the history.
    std::unique_ptr<dealii::FiniteElement<dim>> fe;
    try
      {
        fe = dealii::FETools::get_fe_by_name<dim, dim>(header.fe_name);
      }
    catch (...)
      {
        AssertThrow(false, ExcMessage("Parameter '" + entry + "': the finite element '" + header.fe_name +
                                      "' of '" + file + "' is unknown to deal.II's FETools::get_fe_by_name."));
      }
    dealii::DoFHandler<dim> dof_handler(triangulation);
    dof_handler.distribute_dofs(*fe);
    const unsigned int n_dofs = fe->n_dofs_per_cell();
    AssertThrow(cells.dof_values.size() == n_cells * n_dofs,
                ExcMessage("Parameter '" + entry + "': '" + file + "' holds " + std::to_string(cells.dof_values.size()) +
                           " displacement values, its " + std::to_string(n_cells) + " cells of " + header.fe_name +
                           " need " + std::to_string(n_cells * n_dofs) + "."));
    dealii::IndexSet relevant;
    dealii::DoFTools::extract_locally_relevant_dofs(dof_handler, relevant);
    dealii::LinearAlgebra::distributed::Vector<double> displacement(dof_handler.locally_owned_dofs(), relevant,
                                                                    communicator);
    dealii::Vector<double> local(n_dofs);
    for (const auto &cell : dof_handler.active_cell_iterators())
      if (!cell->is_artificial())
        {
          // Coarse cells keep the order they were created in: cell c of the file.
          const std::size_t c = cell->index();
          std::copy(cells.dof_values.begin() + c * n_dofs, cells.dof_values.begin() + (c + 1) * n_dofs,
                    local.begin());
          cell->set_dof_values(local, displacement);
        }
    displacement.update_ghost_values();

    std::vector<dealii::Point<dim>> points(n_q);
    for (unsigned int q = 0; q < n_q; ++q)
      for (int d = 0; d < dim; ++d)
        points[q][d] = header.quadrature_points[q * dim + d];
    const dealii::Quadrature<dim> quadrature(points, header.quadrature_weights);
    const QuadraturePointStateFunction<dim> state =
      [&cells, &header, n_q](const typename dealii::DoFHandler<dim>::active_cell_iterator &cell, const unsigned int q) {
        QuadraturePointState s;
        const std::size_t    width = n_voigt + 1 + header.n_state_variables;
        const double        *value = &cells.states[(cell->index() * n_q + q) * width];
        std::copy(value, value + n_voigt, s.stress);
        s.plastic_strain = value[n_voigt];
        s.state_variables.assign(value + n_voigt + 1, value + width);
        return s;
      };

    for (const unsigned int id : cells.material_ids)
      AssertThrow(parameters.initial_state.materials.count(id),
                  ExcMessage("Parameter 'Initial state/Materials': cells of '" + file + "' have material_id " +
                             std::to_string(id) + ", which it does not map to an MPM material ('" +
                             std::to_string(id) + ": name, density')."));
    std::map<dealii::types::material_id, HandoverMaterial> materials;
    for (const auto &[id, material] : parameters.initial_state.materials)
      materials[id] = HandoverMaterial{material.first, material.second};

    std::vector<GeneratedBody<dim>> bodies(1);
    if (parameters.initial_state.placement == "lattice")
      bodies[0] = points_on_lattice(dof_handler, displacement, quadrature, state, materials,
                                    lattice_handover<dim>(parameters, parameters.initial_state.points_per_direction,
                                                          parameters.initial_state.projection_degree));
    else
      bodies[0] = points_at_quadrature_points(dof_handler, displacement, quadrature, state, materials);
    return bodies;
  }

  template std::vector<GeneratedBody<2>> load_fem_state_points<2>(const Parameters &, MPI_Comm);
  template std::vector<GeneratedBody<3>> load_fem_state_points<3>(const Parameters &, MPI_Comm);
} // namespace mpm
