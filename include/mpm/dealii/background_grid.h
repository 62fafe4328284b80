// The background grid as deal.II sees it: a p4est triangulation of a uniform
// Cartesian box, a Q1 DoFHandler whose vertex DoFs are the MPM nodes, nodal fields
// as distributed vectors over the locally relevant DoFs, and the lattice lookup and
// boundary masks that the core's GridView reads.
#pragma once

#include <mpm/core/views.h>
#include <mpm/dealii/parameters.h>

#include <deal.II/base/partitioner.h>
#include <deal.II/distributed/tria.h>
#include <deal.II/dofs/dof_handler.h>
#include <deal.II/fe/fe_q.h>
#include <deal.II/fe/mapping_q1.h>
#include <deal.II/lac/la_parallel_vector.h>

#include <map>
#include <memory>
#include <vector>

namespace mpm
{
  template <int dim>
  class BackgroundGrid
  {
  public:
    using Vector = dealii::LinearAlgebra::distributed::Vector<double>;

    BackgroundGrid(const Parameters &parameters, MPI_Comm communicator);

    // Active cell of the triangulation at lattice cell index i + n_x (j + n_y k),
    // or an invalid iterator where this rank does not own the cell.
    typename dealii::Triangulation<dim>::active_cell_iterator owned_cell(long lattice_cell) const;

    long lattice_cell_of(const double *x) const;


    mpm::GridView<dim, double> view();

    // Sums ghost-node contributions to their owners and sends the sums back
    // (deal.II's compress(add) + update_ghost_values). Called by the step.
    struct Exchange
    {
      const BackgroundGrid *grid;
      template <typename Real>
      void sum_nodal(Real *const *arrays, const int count) const
      {
        grid->sum_nodal(arrays, count);
      }
    };
    Exchange exchange() const { return Exchange{this}; }

    MPI_Comm                                  communicator;
    dealii::parallel::distributed::Triangulation<dim> triangulation;
    dealii::FE_Q<dim>                         fe;
    dealii::DoFHandler<dim>                   dof_handler;
    dealii::MappingQ1<dim>                    mapping;
    dealii::IndexSet                          locally_owned_dofs, locally_relevant_dofs;
    std::shared_ptr<const dealii::Utilities::MPI::Partitioner> partitioner;

    double origin[dim];
    double h;
    int    n_cells[dim];

    // Nodal fields; their local storage (owned, then ghosts) is the core's node array.
    Vector mass, momentum[dim], force[dim], velocity[dim];

  private:
    void sum_nodal(double *const *arrays, int count) const;
    void sum_nodal(float *const *, int) const {}

    std::vector<int>          lattice_to_node;
    std::vector<std::uint8_t> fixed_components;
    std::vector<typename dealii::Triangulation<dim>::active_cell_iterator> cell_of_lattice_cell;
    std::map<const double *, Vector *> vector_of_array;
  };
} // namespace mpm
