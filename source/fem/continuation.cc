// The executable's path through a pre-failure analysis: the analysis, then the MPM from its
// state through the hand-over API, exactly as a user's own FEM program would hand it over.
#include <mpm/core/material/strength_reduction.h>
#include <mpm/dealii/fem_handover.h>
#include <mpm/dealii/simulator.h>
#include <mpm/fem/continuation.h>
#include <mpm/fem/prefailure_analysis.h>

#include <deal.II/base/conditional_ostream.h>
#include <deal.II/base/mpi.h>

#include <iostream>

namespace mpm::fem
{
  using namespace dealii;

  namespace
  {
    template <int dim>
    void run(const Parameters &parameters, const MPI_Comm communicator)
    {
      ConditionalOStream          pcout(std::cout, Utilities::MPI::this_mpi_process(communicator) == 0);
      PrefailureAnalysis<dim>     analysis(parameters, communicator);
      const PrefailureResult      result = analysis.run();
      const PrefailureParameters &p      = parameters.prefailure;
      if (!p.continue_with_mpm)
        return;

      double factor = p.mpm_strength_factor;
      if (p.mpm_strength_from_failure)
        {
          AssertThrow(std::isfinite(result.failing_factor),
                      ExcMessage("Parameter 'Pre-failure analysis/MPM strength factor': 'failing factor', but the "
                                 "strength reduction found no failure up to Maximum factor; raise it or give a "
                                 "number."));
          factor = result.failing_factor;
        }
      Parameters mpm = parameters;
      for (MaterialParameters<double> &m : mpm.materials)
        m = with_reduced_strength(m, factor);

      std::map<types::material_id, HandoverMaterial> handover;
      for (const auto &[id, m] : analysis.materials())
        handover[id] = {m.mpm_material, m.density};
      const QuasiStaticSolver<dim> &solver = analysis.solver();
      GeneratedBody<dim> body = points_at_quadrature_points(solver.dof_handler(), solver.displacement(),
                                                            solver.quadrature(), solver.state_function(), handover);
      pcout << "Hand-over to the MPM: "
            << Utilities::MPI::sum(static_cast<unsigned long>(body.points.size()), communicator)
            << " material points, one per quadrature point, with the FEM's "
            << (p.analysis == Analysis::strength_reduction ?
                  "state at the last converged factor F = " + std::to_string(result.factor_of_safety) :
                  std::string("state after ") + to_string(p.analysis))
            << "; the MPM's strengths are the prm's divided by " << factor << std::endl;
      Simulator<dim> simulator(mpm, communicator);
      simulator.setup({std::move(body)});
      while (!simulator.finished())
        simulator.advance();
      simulator.finish();
    }
  } // namespace

  void run_prefailure_analysis(const Parameters &parameters, const MPI_Comm communicator)
  {
    if (parameters.dim == 2)
      run<2>(parameters, communicator);
    else
      run<3>(parameters, communicator);
  }
} // namespace mpm::fem
