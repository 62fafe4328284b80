// The FEM stage does not depend on the number of MPI ranks: the strength reduction of a
// Drucker-Prager slope (V7's geometry, 2 m cells) on every rank of MPI_COMM_WORLD against the
// same analysis on rank 0 alone (MPI_COMM_SELF):
//  - the same factor of safety (to the Factor tolerance, 0.005),
//  - the same stresses at every quadrature point of the state at the last converged factor,
//    to 1e-8 of gamma H (matched by the quadrature point's position).
// ctest runs it on 2 and 4 ranks.
#include <mpm/run/scene.h>
#include <mpm/fem/prefailure_analysis.h>

#include "v7_slope_prm.h"

#include <deal.II/base/mpi.h>
#include <deal.II/fe/fe_values.h>

#include <array>
#include <cmath>
#include <iomanip>
#include <iostream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

using namespace dealii;

namespace
{
  constexpr double gamma_H = 2038.7359836901 * 9.81 * 10;

  std::string slope(const std::string &directory)
  {
    return v7_drucker_prager_slope("  set Method = strength reduction", directory);
  }

  using Stresses = std::map<std::array<long long, 2>, std::array<double, 6>>;

  // The committed stresses of this rank's quadrature points, keyed by position (in 1e-9 m).
  Stresses stresses(const mpm::fem::QuasiStaticSolver<2> &solver)
  {
    FEValues<2> fe_values(solver.dof_handler().get_fe(), solver.quadrature(), update_quadrature_points);
    Stresses    result;
    for (const auto &cell : solver.dof_handler().active_cell_iterators())
      if (cell->is_locally_owned())
        {
          fe_values.reinit(cell);
          for (unsigned int q = 0; q < solver.quadrature().size(); ++q)
            {
              const Point<2>         x = fe_values.quadrature_point(q);
              std::array<double, 6> s;
              for (int c = 0; c < 6; ++c)
                s[c] = solver.history(cell, q).stress[c];
              result[{{std::llround(x[0] * 1e9), std::llround(x[1] * 1e9)}}] = s;
            }
        }
    return result;
  }
} // namespace

int main(int argc, char **argv)
{
  Utilities::MPI::MPI_InitFinalize mpi(argc, argv, 1);
  const unsigned int               rank = Utilities::MPI::this_mpi_process(MPI_COMM_WORLD);
  const unsigned int               np   = Utilities::MPI::n_mpi_processes(MPI_COMM_WORLD);

  mpm::fem::PrefailureAnalysis<2> parallel(mpm::prefailure_scene(mpm::scene_from_string(slope("test-prefailure-np-output"))),
                                           MPI_COMM_WORLD);
  const double F_parallel = parallel.run().factor_of_safety;
  // Every rank's stresses to rank 0.
  const std::vector<Stresses> gathered = Utilities::MPI::gather(MPI_COMM_WORLD, stresses(parallel.solver()), 0);

  int failures = 0;
  if (rank == 0)
    {
      mpm::fem::PrefailureAnalysis<2> serial(mpm::prefailure_scene(mpm::scene_from_string(slope("test-prefailure-np-serial"))),
                                             MPI_COMM_SELF);
      const double   F_serial  = serial.run().factor_of_safety;
      const Stresses reference = stresses(serial.solver());
      std::size_t    matched   = 0;
      double         error     = 0;
      for (const Stresses &part : gathered)
        for (const auto &[x, s] : part)
          {
            const auto found = reference.find(x);
            if (found == reference.end())
              continue;
            ++matched;
            for (int c = 0; c < 6; ++c)
              error = std::max(error, std::abs(s[c] - found->second[c]) / gamma_H);
          }
      const bool same_F = std::abs(F_parallel - F_serial) <= 0.005 + 1e-12;
      const bool all    = matched == reference.size();
      std::cout << (same_F ? "  ok    " : "  FAIL  ") << np << " ranks: F = " << F_parallel << ", 1 rank: F = "
                << F_serial << " (the same to the Factor tolerance 0.005)\n"
                << (all && error < 1e-8 ? "  ok    " : "  FAIL  ") << matched << " of " << reference.size()
                << " quadrature points matched; largest stress difference " << std::scientific
                << std::setprecision(3) << error << " of gamma H (< 1e-8)" << std::endl;
      failures = (same_F ? 0 : 1) + (all && error < 1e-8 ? 0 : 1);
    }
  return Utilities::MPI::broadcast(MPI_COMM_WORLD, failures, 0) == 0 ? 0 : 1;
}
