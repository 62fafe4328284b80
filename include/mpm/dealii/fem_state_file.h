// An FEM state in a file: the route from a user's FEM program to a prm run of the dealii-mpm
// executable (Initial state/Source = FEM file).
//
//   // in the FEM program, after the pre-failure analysis (collective on the mesh's communicator):
//   mpm::save_fem_state("slope.fem-state", dof_handler, displacement, quadrature, history);
//
//   # in the scene's prm file:
//   subsection Initial state
//     set Source    = FEM file
//     set FEM file  = slope.fem-state
//     set Placement = quadrature points          # or: lattice
//     set Materials = 0: soil, 2000               # material_id: MPM material, density; ...
//   end
//
// The file holds the active cells of the mesh (their vertices and material_id), the name of the
// finite element, the displacement's values on each cell, the quadrature rule and the state of
// every quadrature point (stress, plastic strain, state variables), written with boost::serialization (deal.II's serialization) by rank 0
// after a gather, atomically (written beside, then renamed). The executable rebuilds the mesh
// as a parallel::distributed::Triangulation whose coarse cells are the saved cells (p4est
// partitions them over any number of ranks), the FE with FETools::get_fe_by_name, the
// displacement and the history, and hands them over with fem_handover.h or
// fem_handover_lattice.h: the same points as the API gives the FEM program itself.
// Limits: meshes without hanging nodes, cells mapped by MappingQ1 (straight-sided) in the saved
// state, every rank holds the file's contents once while loading.
#pragma once

#include <mpm/dealii/fem_handover.h>
#include <mpm/dealii/parameters.h>

#include <deal.II/base/mpi.h>
#include <deal.II/dofs/dof_handler.h>
#include <deal.II/lac/vector.h>

#include <boost/serialization/version.hpp>

#include <mpi.h>

#include <string>
#include <vector>

namespace mpm
{
  // The cells of one rank, flattened (the unit of the gather and of the file).
  struct FemStateCells
  {
    std::vector<double>       vertices;    // per cell: vertices_per_cell points of dim coordinates
    std::vector<unsigned int> material_ids; // per cell
    std::vector<double>       dof_values;  // per cell: the FE's dofs_per_cell values of the displacement
    std::vector<double>       states;      // per cell: n_q x (n_voigt stresses, plastic strain, state variables)

    template <class Archive>
    void serialize(Archive &ar, const unsigned int)
    {
      ar &vertices &material_ids &dof_values &states;
    }
  };

  // What describes the whole state besides the cells.
  struct FemStateHeader
  {
    unsigned int        dim = 0;
    std::string         fe_name;
    std::vector<double> quadrature_points; // n_q x dim
    std::vector<double> quadrature_weights;
    unsigned int        n_state_variables = 0; // per quadrature point, besides stress and eps_p

    // Version 1 added the state variables; a version 0 file has none.
    template <class Archive>
    void serialize(Archive &ar, const unsigned int version)
    {
      ar &dim &fe_name &quadrature_points &quadrature_weights;
      if (version >= 1)
        ar &n_state_variables;
    }
  };

  // Gathers every rank's cells to rank 0 and writes the file (collective).
  void write_fem_state_file(const std::string &filename, const FemStateHeader &header, const FemStateCells &cells,
                            MPI_Comm communicator);

  // Saves the state of a DoFHandler's mesh as the executable reads it. Collective on the
  // DoFHandler's communicator; each rank gives its locally owned cells. Throws naming what is
  // wrong (the checks of the hand-over, hanging nodes, a file that cannot be written).
  template <int dim, typename VectorType>
  void save_fem_state(const std::string &filename, const dealii::DoFHandler<dim> &dof_handler,
                      const VectorType &displacement, const dealii::Quadrature<dim> &quadrature,
                      const QuadraturePointStateFunction<dim> &state)
  {
    internal::check_handover_input(dof_handler, displacement, state);
    AssertThrow(!dof_handler.get_triangulation().has_hanging_nodes(),
                dealii::ExcMessage("save_fem_state: the mesh has hanging nodes, which the FEM file cannot hold yet "
                                   "(its cells become the coarse cells of the executable's mesh)."));
    FemStateHeader header;
    header.dim     = dim;
    header.fe_name = dof_handler.get_fe().get_name();
    for (unsigned int q = 0; q < quadrature.size(); ++q)
      {
        for (int d = 0; d < dim; ++d)
          header.quadrature_points.push_back(quadrature.point(q)[d]);
        header.quadrature_weights.push_back(quadrature.weight(q));
      }
    FemStateCells          cells;
    dealii::Vector<double> local(dof_handler.get_fe().n_dofs_per_cell());
    bool                   first = true;
    std::string            mismatch; // what is wrong with this rank's state, if anything
    for (const auto &cell : dof_handler.active_cell_iterators())
      if (cell->is_locally_owned())
        {
          for (const unsigned int v : cell->vertex_indices())
            for (int d = 0; d < dim; ++d)
              cells.vertices.push_back(cell->vertex(v)[d]);
          cells.material_ids.push_back(cell->material_id());
          cell->get_dof_values(displacement, local);
          cells.dof_values.insert(cells.dof_values.end(), local.begin(), local.end());
          for (unsigned int q = 0; q < quadrature.size(); ++q)
            {
              const QuadraturePointState s = state(cell, q);
              if (first)
                header.n_state_variables = s.state_variables.size();
              first = false;
              if (s.state_variables.size() != header.n_state_variables && mismatch.empty())
                mismatch = "quadrature point " + std::to_string(q) + " of cell " + cell->id().to_string() +
                           " gives " + std::to_string(s.state_variables.size()) +
                           " state variable(s), the first quadrature point " +
                           std::to_string(header.n_state_variables) + ".";
              cells.states.insert(cells.states.end(), s.stress, s.stress + n_voigt);
              cells.states.push_back(s.plastic_strain);
              cells.states.insert(cells.states.end(), s.state_variables.begin(), s.state_variables.end());
            }
        }
    // One count on every rank (a rank without cells takes the others'); a refusal on any rank
    // stops every rank before the collective write.
    const MPI_Comm     comm = dof_handler.get_communicator();
    const unsigned int most = dealii::Utilities::MPI::max(header.n_state_variables, comm);
    if (!first && header.n_state_variables != most && mismatch.empty())
      mismatch = "the MPI ranks' quadrature points give different numbers of state variables (" +
                 std::to_string(header.n_state_variables) + " here, " + std::to_string(most) + " elsewhere).";
    header.n_state_variables = most;
    const bool refused_anywhere = dealii::Utilities::MPI::max(mismatch.empty() ? 0 : 1, comm) > 0;
    AssertThrow(mismatch.empty(), dealii::ExcMessage("save_fem_state: " + mismatch));
    AssertThrow(!refused_anywhere, dealii::ExcMessage("save_fem_state: another MPI rank's state was refused (its "
                                                      "message says why)."));
    write_fem_state_file(filename, header, cells, comm);
  }

  // The same with the states in deal.II's CellDataStorage.
  template <int dim, typename VectorType, typename CellIteratorType, typename DataType>
  void save_fem_state(const std::string &filename, const dealii::DoFHandler<dim> &dof_handler,
                      const VectorType &displacement, const dealii::Quadrature<dim> &quadrature,
                      const dealii::CellDataStorage<CellIteratorType, DataType> &history)
  {
    save_fem_state(filename, dof_handler, displacement, quadrature, internal::state_from_storage<dim>(history));
  }

  // The points of the FEM file that parameters' Initial state names, in its placement, for
  // Simulator::setup(bodies). Collective; each rank returns those of its share of the cells.
  template <int dim>
  std::vector<GeneratedBody<dim>> load_fem_state_points(const Parameters &parameters, MPI_Comm communicator);
} // namespace mpm

BOOST_CLASS_VERSION(mpm::FemStateHeader, 1)
