// The pre-failure analysis a scene asks for (PrefailureScene; in a parameter file, subsection
// Pre-failure analysis, read by run/scene.h): the mesh, the solver, then gravity loading, the
// K0 procedure or a shear strength reduction, with its log and output files (its output folder):
//   prefailure_initial_*.pvtu        the state after gravity loading or the K0 procedure
//   strength_reduction.csv           factor, converged, iterations, monitor displacement, ...
//   prefailure_failure_mechanism_*.pvtu  the state at the last converged factor
// The committed state is then the one the MPM can take over (solver().state_function()).
#pragma once

#include <mpm/fem/prefailure_scene.h>
#include <mpm/fem/quasi_static_solver.h>

#include <deal.II/distributed/tria.h>

#include <limits>
#include <memory>
#include <string>
#include <vector>

namespace mpm::fem
{
  // One factor tried by the strength reduction.
  struct ReductionStep
  {
    double       factor;
    bool         converged;
    unsigned int iterations;
    double       residual;             // Newton's last relative residual
    double       monitor_displacement; // m, since the start of the reduction (committed state)
    double       max_plastic_strain;   // of the committed state
    double       wall_seconds;
    unsigned int initial_stiffness_iterations = 0; // after a failed Newton (quasi_static_solver.h)
  };

  struct PrefailureResult
  {
    // Gravity loading / K0 procedure (the initial stresses of a strength reduction).
    std::vector<NewtonReport> initial_steps;
    double                    k0_residual = 0; // K0 procedure: the stresses' relative residual before the equilibrium step
    // Strength reduction: the last converged factor and the lowest failing one (infinity if
    // none failed up to Maximum factor).
    double                     factor_of_safety = 0;
    double                     failing_factor   = std::numeric_limits<double>::infinity();
    std::vector<ReductionStep> curve;
    double                     wall_seconds = 0;
    std::vector<std::string>   files;
  };

  template <int dim>
  class PrefailureAnalysis
  {
  public:
    PrefailureAnalysis(const PrefailureScene &scene, MPI_Comm communicator);

    // Runs the analysis of Pre-failure analysis/Method and writes its files; throws where the
    // body cannot carry its initial load (naming what to change).
    PrefailureResult run();

    const QuasiStaticSolver<dim> &solver() const;
    QuasiStaticSolver<dim>       &solver();
    // The materials of the mesh's material ids (MPM index and density for the hand-over).
    const std::map<dealii::types::material_id, FemMaterial> &materials() const;

  private:
    void initial_stresses(double strength_factor, PrefailureResult &result);
    void strength_reduction(PrefailureResult &result);
    void write_curve(const PrefailureResult &result) const;

    const PrefailureScene                              scene;
    MPI_Comm                                           communicator;
    dealii::parallel::distributed::Triangulation<dim> triangulation;
    std::map<dealii::types::material_id, FemMaterial> fem_materials;
    std::unique_ptr<QuasiStaticSolver<dim>>            quasi_static;
  };
} // namespace mpm::fem
