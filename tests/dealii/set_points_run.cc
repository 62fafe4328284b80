// Simulator::set_points on any number of MPI ranks: the reduced 2D collapse
// (tests/prm/collapse_small_2d.prm, 3,200 points) set up, its points shifted 0.2 m along x (the
// column's own length: most points land in cells that another rank owns when there are two) and
// given 0.5 m/s along x, written back, then 40 steps. Writes the particle tables into the folder
// given; ctest runs it on 1 and 2 ranks and compare_np.py asserts the points agree. Here it checks
// that the points moved where they were put (centre of mass, over all ranks) and, on several
// ranks, that points changed rank (the count per rank changed) and no point was lost.
#include "../core/check.h"

#include <mpm/dealii/parameters.h>
#include <mpm/dealii/simulator.h>

#include <deal.II/base/mpi.h>

#include <cstdio>
#include <string>

using namespace mpm;
using mpm_test::check;
using mpm_test::check_below;

int main(int argc, char **argv)
{
  dealii::Utilities::MPI::MPI_InitFinalize mpi(argc, argv, 1);
  const MPI_Comm                           comm = MPI_COMM_WORLD;
  try
    {
      AssertThrow(argc == 2, dealii::ExcMessage("usage: set_points_run OUTPUT_DIRECTORY"));
      Parameters p = read_parameters(std::string(MPM_SOURCE_DIR) + "/tests/prm/collapse_small_2d.prm");
      p.max_steps            = 40;
      p.output.directory     = argv[1];
      p.output.interval      = 0;
      p.output.progress_interval    = 0;
      p.output.write_particle_table = true;
      Simulator<2> simulator(p, comm);
      simulator.setup();

      // Sums over all ranks: points, mass and first moment of mass along x.
      const auto totals = [&](const HostPoints<2, double> &q) {
        double local[3] = {double(q.size()), 0, 0}, global[3];
        for (int i = 0; i < q.size(); ++i)
          local[1] += q.mass[i], local[2] += q.mass[i] * q.position[0][i];
        dealii::Utilities::MPI::sum(dealii::ArrayView<const double>(local, 3), comm,
                                    dealii::ArrayView<double>(global, 3));
        return std::array<double, 3>{{global[0], global[1], global[2] / global[1]}};
      };
      HostPoints<2, double>       points = simulator.points();
      const std::array<double, 3> before = totals(points);
      const int                   here   = points.size();
      const double                shift = 0.2, speed = 0.5;
      for (int i = 0; i < points.size(); ++i)
        {
          points.position[0][i] += shift;
          points.velocity[0][i] = speed;
        }
      simulator.set_points(points);
      const HostPoints<2, double> after_set = simulator.points();
      const std::array<double, 3> after     = totals(after_set);
      const int changed = dealii::Utilities::MPI::max(after_set.size() != here ? 1 : 0, comm);
      if (dealii::Utilities::MPI::this_mpi_process(comm) == 0)
        std::printf("set_points on %u rank(s): %g points before, %g after; centre of mass x %.9f -> %.9f m; points "
                    "per rank changed: %s\n",
                    dealii::Utilities::MPI::n_mpi_processes(comm), before[0], after[0], before[2], after[2],
                    changed ? "yes" : "no");
      check(after[0] == before[0], "no point lost or doubled by set_points");
      check_below(std::abs(after[2] - before[2] - shift), 1e-12, "the points are where they were put");
      if (dealii::Utilities::MPI::n_mpi_processes(comm) > 1)
        check(changed == 1, "on several ranks, points moved to another rank's cells changed rank");
      bool moving = true;
      for (int i = 0; i < after_set.size(); ++i)
        moving = moving && after_set.velocity[0][i] == speed;
      check(dealii::Utilities::MPI::min(moving ? 1 : 0, comm) == 1, "every point carries the velocity given");

      while (!simulator.finished())
        simulator.advance();
      simulator.finish();
    }
  catch (const std::exception &e)
    {
      std::printf("exception: %s\n", e.what());
      return 1;
    }
  return mpm_test::finish("set_points_run");
}
