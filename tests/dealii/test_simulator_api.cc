// The run's C++ API (simulator.h) on the reduced 2D collapse (tests/prm/collapse_small_2d.prm,
// 3,200 points, Drucker-Prager), 60 steps:
//  - stepped by a program (setup, advance until finished, finish) it gives the points of run()
//    (the executable's path, which builds deal.II's grid beside the first steps) to the last bit;
//  - points() then set_points() of the same values changes nothing; a changed field reaches the
//    step (a velocity given to every point moves the body's centre of mass by v dt in the next
//    step, up to the step's own motion);
//  - misuse stops with a message: set_points with another number of points or a point outside
//    the grid, advance() before setup(), setup() twice.
#include "../core/check.h"

#include <mpm/dealii/parameters.h>
#include <mpm/dealii/simulator.h>

#include <deal.II/base/mpi.h>

#include <cmath>
#include <cstdio>
#include <string>

using namespace mpm;
using mpm_test::check;
using mpm_test::throws_naming;
using mpm_test::check_below;

namespace
{
  Parameters scene(const std::string &directory)
  {
    Parameters p = read_parameters(std::string(MPM_SOURCE_DIR) + "/tests/prm/collapse_small_2d.prm");
    p.max_steps            = 60;
    p.output.directory     = directory;
    p.output.interval      = 0;
    p.output.progress_interval    = 0;
    p.output.write_particles      = false;
    p.output.write_grid_fields    = false;
    return p;
  }

  double largest_difference(const HostPoints<2, double> &a, const HostPoints<2, double> &b)
  {
    double worst = a.size() == b.size() ? 0 : 1e300;
    for (int i = 0; i < a.size() && i < b.size(); ++i)
      for (int d = 0; d < 2; ++d)
        worst = std::max({worst, std::abs(a.position[d][i] - b.position[d][i]),
                          std::abs(a.velocity[d][i] - b.velocity[d][i])});
    for (int i = 0; i < a.size() && i < b.size(); ++i)
      for (int c = 0; c < n_voigt; ++c)
        worst = std::max(worst, std::abs(a.stress[c][i] - b.stress[c][i]));
    return worst;
  }

} // namespace

int main(int argc, char **argv)
{
  dealii::Utilities::MPI::MPI_InitFinalize mpi(argc, argv, 1);
  try
    {
      Simulator<2> whole(scene("output-api-run"), MPI_COMM_WORLD);
      whole.run();
      const HostPoints<2, double> by_run = whole.points();

      Simulator<2> stepped(scene("output-api-stepped"), MPI_COMM_WORLD);
      stepped.setup();
      while (!stepped.finished())
        stepped.advance();
      stepped.finish();
      const HostPoints<2, double> by_steps = stepped.points();
      std::printf("run() and setup/advance/finish after %ld and %ld steps: largest difference %.3e\n", whole.step(),
                  stepped.step(), largest_difference(by_run, by_steps));
      check(whole.step() == 60 && stepped.step() == 60, "both stop at Maximum number of steps");
      check(largest_difference(by_run, by_steps) == 0, "stepping from a program gives run()'s points exactly");

      // Writing the points back unchanged changes nothing; a velocity reaches the next step.
      Simulator<2> moved(scene("output-api-moved"), MPI_COMM_WORLD), kept(scene("output-api-kept"), MPI_COMM_WORLD);
      moved.setup();
      kept.setup();
      HostPoints<2, double> p = moved.points();
      moved.set_points(p);
      check(largest_difference(moved.points(), kept.points()) == 0, "set_points(points()) changes nothing");
      const double v = 0.01;
      for (int i = 0; i < p.size(); ++i)
        p.velocity[0][i] += v;
      moved.set_points(p);
      auto centre = [](const HostPoints<2, double> &q) {
        double mx = 0, m = 0;
        for (int i = 0; i < q.size(); ++i)
          mx += q.mass[i] * q.position[0][i], m += q.mass[i];
        return mx / m;
      };
      const double dt      = moved.advance();
      const double dt_kept = kept.advance();
      const double shift   = centre(moved.points()) - centre(kept.points());
      std::printf("a velocity of %g m/s given to every point: centre of mass moved %.6e m further in a step of "
                  "%.6e s (v dt = %.6e m)\n",
                  v, shift, dt, v * dt);
      check(dt == dt_kept, "the same time step");
      // The no-slip base holds the points next to it: the shift is a little less than v dt.
      check(shift > 0.5 * v * dt && shift <= 1.000001 * v * dt, "the given velocity moves the body", shift, v * dt);

      // Misuse.
      HostPoints<2, double> fewer = moved.points();
      fewer.resize(fewer.size() - 1);
      check(throws_naming([&]() { moved.set_points(fewer); }, "3199 points given, the run holds 3200"),
            "set_points with another number of points is refused, naming both counts");
      HostPoints<2, double> outside = moved.points();
      outside.position[1][7] = 0.13; // the grid ends at y = 0.12
      check(throws_naming([&]() { moved.set_points(outside); }, "point 7 at y = 0.13 lies outside the grid"),
            "set_points with a point outside the grid is refused, naming the point and the grid");
      Simulator<2> fresh(scene("output-api-fresh"), MPI_COMM_WORLD);
      check(throws_naming([&]() { fresh.advance(); }, "needs setup() first"), "advance() before setup()");
      fresh.setup();
      check(throws_naming([&]() { fresh.setup(); }, "setup() was called twice"), "setup() twice");
    }
  catch (const std::exception &e)
    {
      std::printf("exception: %s\n", e.what());
      return 1;
    }
  return mpm_test::finish("test_simulator_api");
}
