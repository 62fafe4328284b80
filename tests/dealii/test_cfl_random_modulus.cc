// The explicit step's CFL condition with a Young's modulus that varies from point to point
// (Material/Random field/Parameter = Young's modulus): the first time step must be
// CFL number x h / c_max, c_max = max over the points of sqrt((K + 4G/3)(E_p) / rho), so that
// no point runs beyond the CFL number the user set. The material's mean modulus gives a longer
// step (a point with E above the mean then runs at CFL x sqrt(E_p / E_mean)).
// An elastic block at rest (|v| = 0: the first step is set by the elastic wave alone), E with
// mean 10 MPa and standard deviation 3 MPa; on one rank and, the points generated on each rank
// whole, the same step on two.
#include "../core/check.h"

#include <mpm/core/material/material.h>
#include <mpm/dealii/parameters.h>
#include <mpm/dealii/simulator.h>

#include <deal.II/base/mpi.h>

#include <algorithm>
#include <cmath>
#include <string>

using namespace mpm;
using mpm_test::check;

namespace
{
  const char *scene = R"(
set Dimension = 2
subsection Grid
  set Lower corner = 0, 0
  set Upper corner = 8, 4
  set Cell size    = 0.25
end
subsection Solver
  set End time = 1
  set CFL number = 0.4
end
subsection Materials
  set Names = soil
end
subsection Material soil
  set Model = linear elastic
  subsection linear elastic
    set Young's modulus = 1e7
    set Poisson's ratio = 0.3
  end
  subsection Random field
    set Parameter           = Young's modulus
    set Correlation lengths = 0.5, 0.5
    set Standard deviation  = 3e6
    set Seed                = 11
  end
end
subsection Material points
  set Number of bodies = 1
  subsection Body 1
    set Lower corner = 1, 0
    set Upper corner = 7, 3
    set Density      = 2000
    set Material     = soil
  end
end
subsection Output
  set Directory = output-cfl-random-modulus
  set Output interval = 0
  set Write particles = false
  set Write grid fields = false
  set Progress interval = 0
end
)";
} // namespace

int main(int argc, char **argv)
{
  dealii::Utilities::MPI::MPI_InitFinalize mpi(argc, argv, 1);
  const MPI_Comm                           comm = MPI_COMM_WORLD;
  try
    {
      const Parameters p = parameters_from_string(scene);
      Simulator<2>     run(p, comm);
      run.setup();
      const HostPoints<2, double> points = run.points(); // before the step: the points at rest
      const double                dt     = run.advance();

      const MaterialParameters<double> &soil = p.materials[0];
      double c_max = 0, E_max = 0, E_sum = 0;
      for (int i = 0; i < points.size(); ++i)
        {
          const double E = points.material_field[i];
          E_max          = std::max(E_max, E);
          E_sum += E;
          MaterialParameters<double> own = soil;
          own.elastic.youngs_modulus     = E;
          c_max = std::max(c_max, std::sqrt(own.elastic.p_wave_modulus() / p.bodies[0].density));
        }
      c_max = dealii::Utilities::MPI::max(c_max, comm);
      E_max = dealii::Utilities::MPI::max(E_max, comm);
      const double n      = dealii::Utilities::MPI::sum(double(points.size()), comm);
      const double E_mean = dealii::Utilities::MPI::sum(E_sum, comm) / n;
      const double wanted = p.cfl * p.cell_size / c_max;
      // The field must reach well above its mean, or the test could not tell the two steps apart.
      check(E_max > 1.3 * E_mean, "the random field reaches 30% above its mean", E_max / E_mean, 1.3);
      check(std::abs(dt - wanted) <= 1e-12 * wanted, "first time step = CFL h / max over points c_el", dt, wanted);
      // The stiffest point's own Courant number: the CFL number set, not beyond.
      const double courant = dt * c_max / p.cell_size;
      check(courant <= p.cfl * (1 + 1e-12), "the stiffest point's Courant number <= CFL number", courant, p.cfl);
      if (dealii::Utilities::MPI::this_mpi_process(comm) == 0)
        std::printf("E mean %.4e, max %.4e Pa; c_max %.2f m/s; dt %.6e s (CFL h / c_max %.6e s); Courant %.4f\n",
                    E_mean, E_max, c_max, dt, wanted, courant);
      run.finish();
    }
  catch (const std::exception &e)
    {
      std::printf("unexpected exception: %s\n", e.what());
      return 1;
    }
  return mpm_test::finish("test_cfl_random_modulus");
}
