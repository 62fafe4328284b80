// Strength reduction of an infinite slope against its analytic factor of safety
// (doc/prefailure.md, "Validation"). A layer of depth H on a fixed base, periodic along the
// slope (one slice stands for the whole slope), under gravity tilted by beta: every column is
// the same, and at the base sigma_n = gamma H cos(beta), tau = gamma H sin(beta) exactly.
//  1. Associated Mohr-Coulomb (psi = phi): the flow is compatible with slip on the plane
//     parallel to the slope, so collapse comes when that plane reaches c + sigma_n tan(phi):
//     F = c / (gamma H sin(beta)) + tan(phi) / tan(beta). 2D (plane strain) and 3D (periodic
//     along x and y), within 2%.
//  2. Mohr-Coulomb with psi = 0: in plane strain, plastic flow without volume change and with
//     no stretch along the slope needs principal axes at 45 degrees, i.e. sigma_xx = sigma_zz,
//     and collapse comes when the Mohr circle of radius tau about sigma_n touches the reduced
//     envelope: tau = c/F cos(phi_F) + sigma_n sin(phi_F), tan(phi_F) = tan(phi)/F, a lower F
//     (Davis' non-associated correction). Within 2%.
// The strength reduction's last step (below twice Factor tolerance, 0.005) bounds how far
// below the true collapse factor the last converged F lies.
#include <mpm/run/scene.h>
#include <mpm/fem/prefailure_analysis.h>

#include <deal.II/base/mpi.h>

#include <cmath>
#include <iomanip>
#include <iostream>
#include <sstream>
#include <string>

using namespace dealii;

namespace
{
  constexpr double pi = 3.14159265358979323846;
  constexpr double rho = 2000, g = 9.81, H = 10, c = 10e3, phi_deg = 30, beta_deg = 25;
  const double     beta = beta_deg * pi / 180, phi = phi_deg * pi / 180;

  std::string slope(const unsigned int dim, const double psi_deg)
  {
    std::ostringstream gravity;
    gravity << std::setprecision(17) << g * std::sin(beta) << ", " << (dim == 3 ? "0, " : "") << -g * std::cos(beta);
    const std::string lo = dim == 2 ? "0, 0" : "0, 0, 0", hi = dim == 2 ? "2, 10" : "2, 1, 10";
    return "set Dimension = " + std::to_string(dim) +
           "\nsubsection Grid\n set Lower corner = " + lo + "\n set Upper corner = " + (dim == 2 ? "2, 12" : "2, 1, 12") +
           "\n set Cell size = 1\nend\n"
           "subsection Solver\n set Gravity = " + gravity.str() + "\nend\n"
           "subsection Material soil\n set Model = mohr coulomb\n subsection mohr coulomb\n"
           "  set Young's modulus = 1e8\n  set Poisson's ratio = 0.3\n  set Cohesion = " + std::to_string(c) +
           "\n  set Friction angle = " + std::to_string(phi_deg) + "\n  set Dilatancy angle = " + std::to_string(psi_deg) +
           "\n end\nend\n"
           "subsection Material points\n subsection Body 1\n  set Lower corner = " + lo +
           "\n  set Upper corner = " + hi + "\n  set Density = " + std::to_string(rho) + "\n end\nend\n"
           // 50 Newton iterations (not 200) before the initial-stiffness ones: the failing factors
           // of the 3D run cost a third of the time, and F is the same to its last digit.
           "subsection Pre-failure analysis\n set Method = strength reduction\n set Load steps = 1\n"
           " set Maximum Newton iterations = 50\n"
           " set Boundary conditions = " + (dim == 2 ? "0: periodic; 1: periodic; 2: fixed" :
                                                        "0: periodic; 1: periodic; 2: periodic; 3: periodic; 4: fixed") +
           "\n set Continue with MPM = false\nend\n"
           "subsection Output\n set Directory = test-infinite-slope-output\nend\n";
  }

  int failures = 0;
  void check(const bool ok, const std::string &what)
  {
    if (Utilities::MPI::this_mpi_process(MPI_COMM_WORLD) == 0)
      std::cout << (ok ? "  ok    " : "  FAIL  ") << what << std::endl;
    failures += ok ? 0 : 1;
  }

  template <int dim>
  double factor_of_safety(const double psi_deg)
  {
    mpm::fem::PrefailureAnalysis<dim> analysis(mpm::prefailure_scene(mpm::scene_from_string(slope(dim, psi_deg))), MPI_COMM_WORLD);
    return analysis.run().factor_of_safety;
  }

  void compare(const std::string &what, const double F, const double expected)
  {
    const double error = std::abs(F - expected) / expected;
    std::ostringstream s;
    s << std::setprecision(4) << what << ": F = " << F << ", analytic " << expected << ", difference "
      << 100 * error << "% (< 2%)";
    check(error < 0.02, s.str());
  }
} // namespace

int main(int argc, char **argv)
{
  Utilities::MPI::MPI_InitFinalize mpi(argc, argv, 1);
  const double gamma = rho * g, sigma_n = gamma * H * std::cos(beta), tau = gamma * H * std::sin(beta);

  const double associated = c / tau + std::tan(phi) / std::tan(beta);
  compare("2D, associated Mohr-Coulomb", factor_of_safety<2>(phi_deg), associated);
  compare("3D, associated Mohr-Coulomb", factor_of_safety<3>(phi_deg), associated);

  // psi = 0: the F where tau = c/F cos(phi_F) + sigma_n sin(phi_F), by bisection.
  const auto excess = [&](const double F) {
    const double phi_F = std::atan(std::tan(phi) / F);
    return c / F * std::cos(phi_F) + sigma_n * std::sin(phi_F) - tau;
  };
  double lo = 0.5, hi = 5;
  for (int i = 0; i < 100; ++i)
    (excess(0.5 * (lo + hi)) > 0 ? lo : hi) = 0.5 * (lo + hi);
  compare("2D, Mohr-Coulomb with psi = 0", factor_of_safety<2>(0), 0.5 * (lo + hi));
  return failures == 0 ? 0 : 1;
}
