// The hand-over between a pre-failure FEM analysis and the MPM: what one quadrature point of
// the FEM gives the material point that continues it. The one header the FEM stage (fem/) and
// the MPM's deal.II layer (dealii/fem_handover.h, which turns these states into points) share;
// neither includes the other.
#pragma once

#include <mpm/core/config.h>

#include <deal.II/dofs/dof_handler.h>

#include <functional>
#include <vector>

namespace mpm
{
  // The state of one quadrature point as the MPM takes it over.
  struct QuadraturePointState
  {
    // Cauchy stress (Pa, compression negative), Voigt order xx, yy, zz, xy, yz, xz; in 2D
    // (plane strain) give zz as well.
    double stress[n_voigt] = {0, 0, 0, 0, 0, 0};
    // Accumulated equivalent plastic strain (softening reads it).
    double plastic_strain = 0;
    // The further state variables of the MPM material's model, in the order its
    // state_variables() lists them (user_model.h); empty for the built-in models. Every
    // quadrature point gives as many as the run's models declare (Parameters::state_variable_names).
    std::vector<double> state_variables;
  };

  // What the cells of one material_id of the FEM mesh become in the MPM.
  struct HandoverMaterial
  {
    unsigned int material; // index of the MPM material: Materials/Names order of the prm
    double       density;  // kg/m^3 in the mesh's reference configuration
  };

  // The state of quadrature point q of a cell: what an FEM analysis hands over
  // (fem::QuasiStaticSolver::state_function, or a user's own).
  template <int dim>
  using QuadraturePointStateFunction =
    std::function<QuadraturePointState(const typename dealii::DoFHandler<dim>::active_cell_iterator &, unsigned int)>;
} // namespace mpm
