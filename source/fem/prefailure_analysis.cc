#include <mpm/fem/mesh.h>
#include <mpm/fem/prefailure_analysis.h>

#include <deal.II/base/conditional_ostream.h>
#include <deal.II/base/exceptions.h>
#include <deal.II/base/mpi.h>
#include <deal.II/base/timer.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <sstream>

namespace mpm::fem
{
  using namespace dealii;

  namespace
  {
    std::string describe(const NewtonReport &r)
    {
      std::ostringstream s;
      s << (r.converged ? "converged" : "NOT converged") << " in " << r.iterations << " Newton iteration(s), residual "
        << std::scientific << std::setprecision(2) << r.residuals.back();
      if (r.line_search_halvings)
        s << ", " << r.line_search_halvings << " line-search halving(s)";
      if (r.singular_tangent)
        s << ", the tangent's linear solve failed";
      if (r.initial_stiffness_iterations)
        s << "; then " << r.initial_stiffness_iterations << " initial-stiffness iteration(s)";
      s << std::defaultfloat << std::setprecision(3) << " (" << r.wall_seconds << " s)";
      return s.str();
    }
  } // namespace

  template <int dim>
  PrefailureAnalysis<dim>::PrefailureAnalysis(const PrefailureScene &scene, const MPI_Comm communicator)
    : scene(scene)
    , communicator(communicator)
    , triangulation(communicator)
  {
    fem_materials = create_mesh(scene, triangulation);
    if (scene.settings.analysis == Analysis::strength_reduction)
      {
        std::string elastic;
        bool        any_strength = false;
        for (const auto &[id, m] : fem_materials)
          if (built_in_model_is(m.parameters.model, [](auto member) { return decltype(member)::plastic; }, false))
            any_strength = true;
          else
            elastic += (elastic.empty() ? "" : ", ") + m.name;
        AssertThrow(any_strength,
                    ExcMessage("Parameter 'Pre-failure analysis/Method': strength reduction divides c and tan(phi), "
                               "but no material of the mesh has a strength (" + elastic + "); give one a "
                               "strength (Materials/Material <name>/Model = " +
                               built_in_model_names([](auto member) { return decltype(member)::plastic; }) + ")."));
      }
    quasi_static  = std::make_unique<QuasiStaticSolver<dim>>(triangulation, fem_materials, scene.settings,
                                                            scene.gravity);
  }

  template <int dim>
  void PrefailureAnalysis<dim>::initial_stresses(const double strength_factor, PrefailureResult &result)
  {
    const PrefailureParameters &p = scene.settings;
    ConditionalOStream pcout(std::cout, Utilities::MPI::this_mpi_process(communicator) == 0);
    const Analysis     how = p.analysis == Analysis::strength_reduction ? p.initial_stresses : p.analysis;
    if (how == Analysis::k0_procedure)
      {
        quasi_static->set_k0_stresses(p.k0);
        const NewtonReport r = quasi_static->solve(1.0, strength_factor);
        result.k0_residual   = r.residuals.front();
        result.initial_steps.push_back(r);
        pcout << "  K0 procedure: stresses from the overburden, relative residual " << std::scientific
              << std::setprecision(2) << r.residuals.front() << std::defaultfloat << "; equilibrium step "
              << describe(r) << std::endl;
        AssertThrow(r.converged, ExcMessage("Pre-failure analysis: the equilibrium step after the K0 procedure did "
                                            "not converge within Maximum Newton iterations (" +
                                            std::to_string(p.maximum_newton_iterations) +
                                            ") and Maximum initial stiffness iterations (" +
                                            std::to_string(p.maximum_initial_stiffness_iterations) +
                                            "): the body cannot carry its weight with these strengths."));
        return;
      }
    // Load steps of 1/Load steps; a step whose Newton fails is retried in halves (up to
    // max_halvings times), from the last converged load.
    const unsigned int max_halvings = 6;
    double             load = 0, step = 1.0 / p.load_steps;
    unsigned int       halvings = 0;
    while (load < 1 - 1e-12)
      {
        const double       target = std::min(1.0, load + step);
        const NewtonReport r      = quasi_static->solve(target, strength_factor);
        result.initial_steps.push_back(r);
        pcout << "  gravity " << std::setw(6) << std::fixed << std::setprecision(2) << 100 * target
              << std::defaultfloat << "%: " << describe(r) << std::endl;
        if (r.converged)
          {
            load = target;
            continue;
          }
        AssertThrow(++halvings <= max_halvings,
                    ExcMessage("Pre-failure analysis: gravity loading found no equilibrium beyond " +
                               std::to_string(100 * load) + "% of the weight (Newton did not converge within Maximum "
                               "Newton iterations = " + std::to_string(p.maximum_newton_iterations) +
                               ", nor the initial-stiffness iterations within " +
                               std::to_string(p.maximum_initial_stiffness_iterations) +
                               " even in steps of 1/" + std::to_string(p.load_steps << max_halvings) +
                               "): the body cannot carry its own weight" +
                               (strength_factor != 1 ? " at Minimum factor" : std::string()) +
                               " (or raise Load steps / Maximum Newton iterations)."));
        step /= 2;
      }
  }

  template <int dim>
  void PrefailureAnalysis<dim>::strength_reduction(PrefailureResult &result)
  {
    const PrefailureParameters &p = scene.settings;
    ConditionalOStream pcout(std::cout, Utilities::MPI::this_mpi_process(communicator) == 0);
    quasi_static->set_monitor_reference();
    result.curve.push_back({p.minimum_factor, true, result.initial_steps.back().iterations,
                            result.initial_steps.back().residuals.back(), 0.0, quasi_static->max_plastic_strain(),
                            0.0});
    // Adaptive steps in F from the last converged factor: a factor that fails halves
    // the step (the failed factor is tried again from nearer once a smaller step converges);
    // the search ends when the step is halved below Factor tolerance. Every trial starts from
    // the committed state of the last converged factor.
    double low = p.minimum_factor, high = 0, step = p.factor_increment;
    pcout << "  strength reduction: F from " << low << " in steps of " << p.factor_increment
          << ", halved where a factor fails, down to " << p.factor_tolerance << std::endl;
    while (step >= p.factor_tolerance && low < p.maximum_factor)
      {
        const double       factor = std::min(low + step, p.maximum_factor);
        const NewtonReport r      = quasi_static->solve(1.0, factor);
        if (r.converged)
          low = factor;
        else
          step /= 2;
        result.curve.push_back({factor, r.converged, r.iterations, r.residuals.back(),
                                quasi_static->monitor_displacement(p.monitor_point), quasi_static->max_plastic_strain(),
                                r.wall_seconds, r.initial_stiffness_iterations});
        pcout << "    F = " << std::fixed << std::setprecision(4) << factor << std::defaultfloat << ": "
              << describe(r);
        if (r.converged)
          pcout << ", monitor displacement " << std::setprecision(4) << result.curve.back().monitor_displacement
                << " m, max plastic strain " << result.curve.back().max_plastic_strain << std::setprecision(6);
        pcout << std::endl;
      }
    high = std::numeric_limits<double>::infinity(); // the lowest factor above the last converged one that failed
    for (const ReductionStep &s : result.curve)
      if (!s.converged && s.factor > low)
        high = std::min(high, s.factor);
    result.factor_of_safety = low;
    result.failing_factor   = high;
    if (std::isfinite(high))
      pcout << "  factor of safety F = " << std::fixed << std::setprecision(4) << low << " (fails at " << high
            << ")" << std::defaultfloat << std::endl;
    else
      pcout << "  no failure up to Maximum factor = " << p.maximum_factor
            << ": the factor of safety exceeds it" << std::endl;
  }

  template <int dim>
  void PrefailureAnalysis<dim>::write_curve(const PrefailureResult &result) const
  {
    if (Utilities::MPI::this_mpi_process(communicator) != 0)
      return;
    std::ofstream out(scene.output_directory + "/strength_reduction.csv");
    out << "factor,converged,newton_iterations,initial_stiffness_iterations,relative_residual,monitor_displacement,"
           "max_plastic_strain,wall_s\n"
        << std::setprecision(10);
    for (const ReductionStep &s : result.curve)
      out << s.factor << ',' << (s.converged ? 1 : 0) << ',' << s.iterations << ',' << s.initial_stiffness_iterations
          << ',' << s.residual << ',' << s.monitor_displacement << ',' << s.max_plastic_strain << ',' << s.wall_seconds
          << '\n';
    AssertThrow(out, ExcMessage("Cannot write " + scene.output_directory + "/strength_reduction.csv."));
  }

  template <int dim>
  PrefailureResult PrefailureAnalysis<dim>::run()
  {
    Timer                       timer;
    const PrefailureParameters &p = scene.settings;
    ConditionalOStream pcout(std::cout, Utilities::MPI::this_mpi_process(communicator) == 0);
    if (Utilities::MPI::this_mpi_process(communicator) == 0)
      std::filesystem::create_directories(scene.output_directory);
    MPI_Barrier(communicator);
    pcout << "Pre-failure analysis (" << to_string(p.analysis) << "): " << triangulation.n_global_active_cells()
          << " cells, FE_Q(" << p.degree << ")^" << dim << ", " << quasi_static->n_dofs() << " unknowns, "
          << Utilities::MPI::n_mpi_processes(communicator) << " MPI rank(s), linear solver " << p.linear_solver
          << std::endl;

    PrefailureResult result;
    const double     initial_factor = p.analysis == Analysis::strength_reduction ? p.minimum_factor : 1.0;
    initial_stresses(initial_factor, result);
    result.files.push_back(quasi_static->write_output(scene.output_directory, "prefailure_initial"));
    if (p.analysis == Analysis::strength_reduction)
      {
        strength_reduction(result);
        write_curve(result);
        result.files.push_back(scene.output_directory + "/strength_reduction.csv");
        result.files.push_back(
          quasi_static->write_output(scene.output_directory, "prefailure_failure_mechanism"));
      }
    result.wall_seconds = timer.wall_time();
    pcout << "Pre-failure analysis done in " << std::setprecision(3) << result.wall_seconds << " s; files:";
    for (const std::string &f : result.files)
      pcout << ' ' << f;
    pcout << std::setprecision(6) << std::endl;
    return result;
  }

  template <int dim>
  const QuasiStaticSolver<dim> &PrefailureAnalysis<dim>::solver() const
  {
    return *quasi_static;
  }

  template <int dim>
  QuasiStaticSolver<dim> &PrefailureAnalysis<dim>::solver()
  {
    return *quasi_static;
  }

  template <int dim>
  const std::map<types::material_id, FemMaterial> &PrefailureAnalysis<dim>::materials() const
  {
    return fem_materials;
  }

  template class PrefailureAnalysis<2>;
  template class PrefailureAnalysis<3>;
} // namespace mpm::fem
