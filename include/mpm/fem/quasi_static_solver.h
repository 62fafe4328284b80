// The pre-failure FEM stage's solver: implicit, quasi-static, small-strain elasto-plasticity
// on a parallel::distributed::Triangulation (deal.II's step-42 is the pattern). Displacement
// FE_Q(p)^dim; at each quadrature point the core's update (small_strain_update.h: the very
// return mappings of the MPM step) and its consistent tangent; Newton with a backtracking line
// search, and where Newton fails the initial-stiffness method; Trilinos matrices, Amesos KLU or
// GMRES + AMG. Plane strain in 2D (the out-of-plane
// stress is carried at every quadrature point). Theory: doc/prefailure.md.
//
//   QuasiStaticSolver<2> solver(triangulation, materials, scene.settings, scene.gravity);
//   for (unsigned int s = 1; s <= n; ++s)
//     solver.solve(double(s) / n, 1.0);      // gravity in load steps
//   solver.solve(1.0, 1.4);                  // the same with c and tan(phi) divided by 1.4
//
// solve() starts from the committed state (displacement and quadrature-point history) and
// commits the new one only where it converges: a failed factor leaves the last state.
#pragma once

#include <mpm/core/config.h>
#include <mpm/fem/fem_material.h>
#include <mpm/fem/prefailure_parameters.h>
#include <mpm/handover/quadrature_point_state.h>

#include <deal.II/base/quadrature_lib.h>
#include <deal.II/base/quadrature_point_data.h>
#include <deal.II/distributed/tria.h>
#include <deal.II/dofs/dof_handler.h>
#include <deal.II/fe/fe_system.h>
#include <deal.II/lac/affine_constraints.h>
#include <deal.II/lac/trilinos_precondition.h>
#include <deal.II/lac/trilinos_sparse_matrix.h>
#include <deal.II/lac/trilinos_vector.h>

#include <map>
#include <memory>
#include <string>
#include <vector>

namespace mpm::fem
{
  // The committed state of one quadrature point: what the hand-over takes (stress, plastic
  // strain) and the total small strain it belongs to, Voigt xx, yy, zz, xy, yz, xz with
  // tensor shear components (zz, yz, xz zero in plane strain).
  struct QuadraturePointHistory : QuadraturePointState
  {
    double strain[n_voigt] = {0, 0, 0, 0, 0, 0};
  };

  struct NewtonReport
  {
    bool         converged  = false;
    unsigned int iterations = 0; // linear solves taken
    // Residual norm relative to the full gravity load's, before each iteration and at the end.
    std::vector<double> residuals;
    unsigned int        line_search_halvings = 0;
    bool                singular_tangent     = false; // the linear solver failed on the tangent
    // Where Newton failed: the iterations of the initial-stiffness method that followed
    // (0 when Newton converged or the fallback is off).
    unsigned int initial_stiffness_iterations = 0;
    double       wall_seconds                 = 0;
  };

  template <int dim>
  class QuasiStaticSolver
  {
  public:
    // materials: by the triangulation's material ids (mesh.h's create_mesh); gravity: m/s^2.
    QuasiStaticSolver(dealii::parallel::distributed::Triangulation<dim> &triangulation,
                      const std::map<dealii::types::material_id, FemMaterial> &materials,
                      const PrefailureParameters &parameters, const std::vector<double> &gravity);

    // Equilibrium under load_factor x gravity with every strength divided by strength_factor,
    // from the committed state: Newton, then (if it fails) the initial-stiffness iterations;
    // commits the result if either converges.
    NewtonReport solve(double load_factor, double strength_factor);

    // The K0 procedure's stresses: sigma_v = -|g| x the overburden of horizontal layers (the
    // material ids' height ranges, which must not overlap), sigma_h = K0 sigma_v (k0 < 0:
    // nu/(1 - nu) of each material), no shear; displacement, strain and plastic strain zero.
    void set_k0_stresses(double k0);

    // The displacement of the monitor point (the vertex nearest to it; empty: the vertex
    // with the largest) relative to the displacement remembered by set_monitor_reference().
    double monitor_displacement(const std::vector<double> &point) const;
    void   set_monitor_reference();

    // The committed state: the displacement with ghost values, the quadrature-point history.
    const dealii::DoFHandler<dim>             &dof_handler() const;
    const dealii::TrilinosWrappers::MPI::Vector &displacement() const;
    const dealii::Quadrature<dim>             &quadrature() const;
    const QuadraturePointHistory &history(const typename dealii::Triangulation<dim>::cell_iterator &cell,
                                          unsigned int q) const;
    // The state function of the hand-over (fem_handover.h) over this history.
    QuadraturePointStateFunction<dim> state_function() const;

    // The committed state as .vtu/.pvtu (displacement; cell averages of the stress and the
    // plastic strain; material id, subdomain); returns the .pvtu's path.
    std::string write_output(const std::string &directory, const std::string &name) const;

    dealii::types::global_dof_index n_dofs() const;
    // Largest plastic strain of the committed state (over every rank).
    double max_plastic_strain() const;

  private:
    enum class Matrix
    {
      none,
      tangent, // the consistent tangent at u
      elastic  // the elastic stiffness (initial-stiffness iterations)
    };
    // -residual (and a matrix) at displacement u; returns |residual|.
    double assemble(const dealii::TrilinosWrappers::MPI::Vector &u, double load_factor, double strength_factor,
                    Matrix matrix);
    void   solve_linear(const dealii::TrilinosWrappers::SparseMatrix &A, dealii::TrilinosWrappers::MPI::Vector &update);
    // Trilinos AMG for this displacement field (vector-valued, rigid translations as constant modes).
    dealii::TrilinosWrappers::PreconditionAMG::AdditionalData amg_settings() const;
    // From start (Newton's best iterate of this increment): u += K_e^-1 R(u) until |R| is
    // below `Initial stiffness tolerance` x |f_ext| or `Maximum initial stiffness iterations`
    // pass (K_e factorised once per call).
    bool   solve_initial_stiffness(const dealii::TrilinosWrappers::MPI::Vector &start, double load_factor,
                                   double strength_factor, NewtonReport &report);
    void   commit(double strength_factor);
    void   setup_constraints(const PrefailureParameters &parameters);

    MPI_Comm                                  communicator;
    dealii::parallel::distributed::Triangulation<dim> &triangulation;
    std::map<dealii::types::material_id, FemMaterial> materials;
    PrefailureParameters                      settings;
    dealii::Tensor<1, dim>                    gravity;
    dealii::FESystem<dim>                     fe;
    dealii::DoFHandler<dim>                   dofs;
    dealii::QGauss<dim>                       quadrature_formula;
    dealii::IndexSet                          owned, relevant;
    dealii::AffineConstraints<double>         constraints;
    dealii::TrilinosWrappers::SparseMatrix    tangent, elastic_stiffness;
    dealii::TrilinosWrappers::MPI::Vector     residual;              // owned: -R
    dealii::TrilinosWrappers::MPI::Vector     solution, committed;  // ghosted
    dealii::TrilinosWrappers::MPI::Vector     monitor_reference;     // ghosted
    double                                    load_norm = 1;         // |f_ext| at full gravity
    dealii::CellDataStorage<typename dealii::Triangulation<dim>::cell_iterator, QuadraturePointHistory> histories;
  };
} // namespace mpm::fem
