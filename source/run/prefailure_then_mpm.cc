// The executable's path through a pre-failure analysis: the analysis, then the MPM from its
// state through the hand-over API, exactly as a user's own FEM program would hand it over.
#include <mpm/core/material/strength_reduction.h>
#include <mpm/dealii/checkpoint.h>
#include <mpm/dealii/fem_handover.h>
#include <mpm/dealii/simulator.h>
#include <mpm/fem/prefailure_analysis.h>
#include <mpm/run/prefailure_then_mpm.h>

#include <deal.II/base/conditional_ostream.h>
#include <deal.II/base/mpi.h>

#include <iostream>

namespace mpm
{
  using namespace dealii;
  using namespace fem;

  namespace
  {
    // The MPM's parameters: the prm's, with the materials' strengths divided by factor.
    Parameters with_strength_divided(const Parameters &parameters, const double factor)
    {
      Parameters mpm = parameters;
      for (MaterialParameters<double> &m : mpm.materials)
        m = with_reduced_strength(m, factor);
      mpm.strength_divisor = factor;
      return mpm;
    }

    // The MPM's steps to End time from a simulator set up or resumed; false where it was stopped
    // on request (after its checkpoint).
    template <int dim>
    bool step_to_end(Simulator<dim> &simulator, const std::function<void()> &before_mpm)
    {
      if (before_mpm)
        before_mpm();
      while (!simulator.finished())
        simulator.advance();
      simulator.finish();
      return !simulator.stopped();
    }

    // The MPM stage continued from its checkpoint: the analysis is not run again.
    template <int dim>
    bool resume(const Scene &scene, const MPI_Comm communicator, const std::string &resume_from,
                const std::function<void()> &before_mpm)
    {
      const Parameters &parameters = scene.mpm;
      AssertThrow(scene.prefailure.continue_with_mpm,
                  ExcMessage("--resume: Pre-failure analysis/Continue with MPM is false, so this scene has no MPM "
                             "stage and no checkpoints to resume."));
      const RunState checkpoint_state = checkpoint::read_state(checkpoint::find(resume_from));
      // 'failing factor' is the analysis's result, known only from the checkpoint; a number must match it.
      const PrefailureParameters &p = scene.prefailure;
      AssertThrow(p.mpm_strength_from_failure || p.mpm_strength_factor == checkpoint_state.strength_divisor,
                  ExcMessage("Parameter 'Pre-failure analysis/MPM strength factor': it is " +
                             std::to_string(p.mpm_strength_factor) + ", but the checkpoint given to --resume was "
                             "written by an MPM stage whose strengths were divided by " +
                             std::to_string(checkpoint_state.strength_divisor) +
                             ". Resume with the parameter file of the run that wrote it."));
      ConditionalOStream pcout(std::cout, Utilities::MPI::this_mpi_process(communicator) == 0);
      pcout << "Pre-failure analysis: not run again; the MPM resumes with the strengths of the checkpoint's run "
               "(the prm's divided by "
            << checkpoint_state.strength_divisor << ")" << std::endl;
      Simulator<dim> simulator(with_strength_divided(parameters, checkpoint_state.strength_divisor), communicator);
      simulator.resume(resume_from);
      return step_to_end(simulator, before_mpm);
    }

    template <int dim>
    bool run(const Scene &scene, const MPI_Comm communicator, const std::function<void()> &before_mpm)
    {
      ConditionalOStream          pcout(std::cout, Utilities::MPI::this_mpi_process(communicator) == 0);
      PrefailureAnalysis<dim>     analysis(prefailure_scene(scene), communicator);
      const PrefailureResult      result = analysis.run();
      const PrefailureParameters &p      = scene.prefailure;
      if (!p.continue_with_mpm)
        return true;

      double factor = p.mpm_strength_factor;
      if (p.mpm_strength_from_failure)
        {
          AssertThrow(std::isfinite(result.failing_factor),
                      ExcMessage("Parameter 'Pre-failure analysis/MPM strength factor': 'failing factor', but the "
                                 "strength reduction found no failure up to Maximum factor; raise it or give a "
                                 "number."));
          factor = result.failing_factor;
        }
      const Parameters mpm = with_strength_divided(scene.mpm, factor);

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
      return step_to_end(simulator, before_mpm);
    }
  } // namespace

  bool run_prefailure_analysis(const Scene &scene, const MPI_Comm communicator, const std::string &resume_from,
                               const std::function<void()> &before_mpm)
  {
    if (!resume_from.empty())
      return scene.mpm.dim == 2 ? resume<2>(scene, communicator, resume_from, before_mpm) :
                                  resume<3>(scene, communicator, resume_from, before_mpm);
    return scene.mpm.dim == 2 ? run<2>(scene, communicator, before_mpm) : run<3>(scene, communicator, before_mpm);
  }
} // namespace mpm
