// The FEM stage's gravity loading against what is known exactly (doc/prefailure.md):
//  1. an elastic layer under its weight, rollers on the sides, fixed base: sigma_v = -gamma
//     (H - z), sigma_h = nu/(1 - nu) sigma_v, no shear, at every quadrature point to 1e-8 of
//     gamma H with Q2 (whose displacement, quadratic in z, is the exact one); 2D and 3D;
//  2. the K0 procedure on the same layer with K0 = 0.55: its stresses exactly, and the
//     equilibrium step finds them in equilibrium (no Newton iteration, stresses unchanged);
//  3. Newton's rate: a Drucker-Prager slope (psi = 0) loaded by gravity yields at the toe and
//     below the crest; in the last load step the convergence order estimated from successive
//     residuals, log(r_k+1 / r_k) / log(r_k / r_k-1), is >= 1.7 over the last two iterations
//     (quadratic: 2; a tangent that is not the consistent one gives 1).
// On any number of MPI ranks (ctest runs 1 and 2): each rank checks its own quadrature points.
#include <mpm/run/scene.h>
#include <mpm/fem/prefailure_analysis.h>

#include "v7_slope_prm.h"

#include <deal.II/base/mpi.h>
#include <deal.II/fe/fe_values.h>

#include <cmath>
#include <iomanip>
#include <iostream>
#include <sstream>
#include <string>

using namespace dealii;

namespace
{
  constexpr double rho = 2000, g = 9.81, H = 10, nu = 0.3;

  std::string layer(const unsigned int dim, const std::string &method, const std::string &model)
  {
    const std::string lo = dim == 2 ? "0, 0" : "0, 0, 0", hi = dim == 2 ? "4, 10" : "2, 2, 10";
    return "set Dimension = " + std::to_string(dim) +
           "\nsubsection Grid\n set Lower corner = " + lo + "\n set Upper corner = " + (dim == 2 ? "4, 12" : "2, 2, 12") +
           "\n set Cell size = 1\nend\n"
           "subsection Solver\n set Gravity = " + (dim == 2 ? "0, -9.81" : "0, 0, -9.81") + "\nend\n"
           "subsection Material soil\n set Model = " + model + "\n subsection " + model +
           "\n  set Young's modulus = 1e8\n  set Poisson's ratio = 0.3\n" +
           (model == "linear elastic" ? "" : "  set Cohesion = 1e7\n  set Friction angle = 30\n") +
           " end\nend\n"
           "subsection Material points\n subsection Body 1\n  set Lower corner = " + lo +
           "\n  set Upper corner = " + hi + "\n  set Density = 2000\n end\nend\n"
           "subsection Pre-failure analysis\n set Method = " + method +
           "\n set Load steps = 1\n set K0 = 0.55\n set Continue with MPM = false\nend\n"
           "subsection Output\n set Directory = " + "test-prefailure-output" + "\nend\n";
  }

  // Largest deviation of the quadrature-point stresses from sigma_v = -rho g (H - z),
  // sigma_h = K sigma_v, relative to rho g H, over every rank.
  template <int dim>
  double layer_stress_error(const mpm::fem::QuasiStaticSolver<dim> &solver, const double K)
  {
    FEValues<dim> fe_values(solver.dof_handler().get_fe(), solver.quadrature(), update_quadrature_points);
    double        error = 0;
    for (const auto &cell : solver.dof_handler().active_cell_iterators())
      if (cell->is_locally_owned())
        {
          fe_values.reinit(cell);
          for (unsigned int q = 0; q < solver.quadrature().size(); ++q)
            {
              const double sigma_v = -rho * g * (H - fe_values.quadrature_point(q)[dim - 1]);
              const auto  &s       = solver.history(cell, q).stress;
              const double expected[6] = {K * sigma_v, dim == 2 ? sigma_v : K * sigma_v, dim == 2 ? K * sigma_v : sigma_v,
                                          0, 0, 0};
              for (int c = 0; c < 6; ++c)
                error = std::max(error, std::abs(s[c] - expected[c]) / (rho * g * H));
            }
        }
    return Utilities::MPI::max(error, MPI_COMM_WORLD);
  }

  std::string sci(const double x)
  {
    std::ostringstream s;
    s << std::setprecision(3) << std::scientific << x;
    return s.str();
  }

  int failures = 0;
  void check(const bool ok, const std::string &what)
  {
    if (Utilities::MPI::this_mpi_process(MPI_COMM_WORLD) == 0)
      std::cout << (ok ? "  ok    " : "  FAIL  ") << what << std::endl;
    failures += ok ? 0 : 1;
  }

  template <int dim>
  void elastic_layer()
  {
    mpm::fem::PrefailureAnalysis<dim> analysis(mpm::prefailure_scene(mpm::scene_from_string(layer(dim, "gravity loading", "linear elastic"))),
                                               MPI_COMM_WORLD);
    const mpm::fem::PrefailureResult result = analysis.run();
    const double                     error  = layer_stress_error(analysis.solver(), nu / (1 - nu));
    check(result.initial_steps.back().converged && error < 1e-8,
          std::to_string(dim) + "D elastic layer, Q2: stresses against sigma_v = gamma z, sigma_h = nu/(1-nu) sigma_v, "
          "largest error " + sci(error) + " of gamma H (< 1e-8)");
  }

  template <int dim>
  void k0_layer()
  {
    mpm::fem::PrefailureAnalysis<dim> analysis(mpm::prefailure_scene(mpm::scene_from_string(layer(dim, "K0 procedure", "mohr coulomb"))),
                                               MPI_COMM_WORLD);
    const mpm::fem::PrefailureResult result = analysis.run();
    const double                     error  = layer_stress_error(analysis.solver(), 0.55);
    check(result.initial_steps.back().converged && result.initial_steps.back().iterations == 0 &&
            result.k0_residual < 1e-12 && error < 1e-12,
          std::to_string(dim) + "D K0 procedure (K0 = 0.55): residual of its stresses " +
            sci(result.k0_residual) + " (< 1e-12), no Newton iteration, stresses exact to " +
            sci(error) + " (< 1e-12)");
  }

  void newton_rate()
  {
    const std::string prm = v7_drucker_prager_slope("  set Method = gravity loading\n  set Residual tolerance = 1e-12",
                                                    "test-prefailure-output");
    mpm::fem::PrefailureAnalysis<2> analysis(mpm::prefailure_scene(mpm::scene_from_string(prm)), MPI_COMM_WORLD);
    const mpm::fem::PrefailureResult result = analysis.run();
    const std::vector<double>       &r      = result.initial_steps.back().residuals;
    std::string                      history;
    for (const double x : r)
      history += " " + sci(x);
    const std::size_t n = r.size();
    double            order = 0;
    if (n >= 4)
      order = std::min(std::log(r[n - 1] / r[n - 2]) / std::log(r[n - 2] / r[n - 3]),
                       std::log(r[n - 2] / r[n - 3]) / std::log(r[n - 3] / r[n - 4]));
    check(result.initial_steps.back().converged && analysis.solver().max_plastic_strain() > 0 && order >= 1.7,
          "Drucker-Prager slope, last load step: relative residuals" + history + "; order over the last two "
          "iterations " + sci(order) + " (>= 1.7), plastic strain up to " +
          sci(analysis.solver().max_plastic_strain()));
  }
} // namespace

int main(int argc, char **argv)
{
  Utilities::MPI::MPI_InitFinalize mpi(argc, argv, 1);
  elastic_layer<2>();
  elastic_layer<3>();
  k0_layer<2>();
  k0_layer<3>();
  newton_rate();
  return failures == 0 ? 0 : 1;
}
