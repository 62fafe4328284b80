// A shape function added by one file and one line (shape_family.h), through the family's test
// member `test wide linear` (include/mpm/core/shape/test_wide_linear_shape.h): the linear hats
// on GIMP's three-node stencil, the same function as linear with a wider stencil, so everything
// the family derives from its traits is exercised while the physics must not change.
//  - before register_test_shapes() the name is not in Solver/Shape function (refused); after
//    it, it is, and the traits' checks apply (GIMP domain update refused naming the shapes that
//    take it; APIC accepted, as for linear);
//  - the run: a sand block thrown at 2 m/s across a 1 cm grid (40 steps, Drucker-Prager; the
//    engine's sorts every 3 steps; on 2 ranks migration with Re-sort distance = 1, so the points
//    go up to the whole safe distance out of their home cells before they are re-sorted: for
//    linear a whole cell, from where one step more carried points beyond the ghost layer, and
//    the re-sort lost them, until the re-sort also came before that; simulator_state.h).
//    Every point, matched by a tag set from its initial position, must end where the linear
//    run's does, with its velocity and plastic strain, to round-off (the two runs add the same
//    products in different orders where their re-sorts differ). The member's third node always
//    weighs zero, so its run cannot show a wrong safe distance: the first check reads it.
#include "../core/check.h"

#include <mpm/core/migration.h>
#include <mpm/core/point_fields.h>
#include <mpm/dealii/parameters.h>
#include <mpm/dealii/simulator.h>

#include <deal.II/base/mpi.h>

#include <cmath>
#include <cstdio>
#include <map>
#include <string>
#include <vector>

using namespace mpm;
using mpm_test::throws_naming;

namespace
{
  std::string scene(const std::string &solver)
  {
    return R"(
set Dimension = 2
subsection Grid
  set Lower corner = 0, 0
  set Upper corner = 0.4, 0.12
  set Cell size    = 0.01
end
subsection Boundary conditions
  set y min = no-slip
  set y max = free
end
subsection Solver
  set End time = 1
  set Maximum number of steps = 40
  set Gravity = 0, -9.81
  set CFL number = 0.5
)" + solver + R"(
end
subsection Backend
  set Sort interval = 3
end
subsection Parallel
  set Re-sort distance = 1
end
subsection Materials
  set Names = sand
end
subsection Material sand
  set Model = drucker prager
  subsection drucker prager
    set Young's modulus = 1e6
    set Poisson's ratio = 0.3
    set Friction angle  = 20
  end
end
subsection Material points
  set Number of bodies = 1
  subsection Body 1
    set Lower corner = 0, 0
    set Upper corner = 0.2, 0.1
    set Density      = 2650
    set Material     = sand
    set Initial velocity = 2, 0
  end
end
subsection Output
  set Output interval   = 0
  set Write particles   = false
  set Write grid fields = false
end
)";
  }

  void expect(const bool ok, const std::string &what, const double value = 0, const double limit = 0)
  {
    if (ok && dealii::Utilities::MPI::this_mpi_process(MPI_COMM_WORLD) == 0)
      std::printf("ok: %s\n", what.c_str());
    mpm_test::check(ok, what.c_str(), value, limit);
  }

  // Every point's final x, y, v_x, v_y and plastic strain on rank 0, by the tag of its initial position.
  std::map<long, std::vector<double>> run(const std::string &shape)
  {
    Parameters p = parameters_from_string(scene("  set Shape function = " + shape));
    p.point_fields.insert(PointField::test_tag);
    Simulator<2> simulator(p, MPI_COMM_WORLD);
    simulator.setup();
    HostPoints<2, double> points = simulator.points();
    for (int i = 0; i < points.size(); ++i) // points on a 5 mm lattice: a unique integer
      points.test_tag[i] = std::round(points.position[0][i] / 2.5e-3) + 1000 * std::round(points.position[1][i] / 2.5e-3);
    simulator.set_points(points);
    while (!simulator.finished())
      simulator.advance();
    points = simulator.points();
    simulator.finish();
    std::vector<double> rows;
    for (int i = 0; i < points.size(); ++i)
      rows.insert(rows.end(), {points.test_tag[i], points.position[0][i], points.position[1][i],
                               points.velocity[0][i], points.velocity[1][i], points.plastic_strain[i]});
    std::map<long, std::vector<double>> by_tag;
    for (const std::vector<double> &part : dealii::Utilities::MPI::gather(MPI_COMM_WORLD, rows))
      for (std::size_t k = 0; k + 6 <= part.size(); k += 6)
        by_tag[static_cast<long>(part[k])] = std::vector<double>(part.begin() + k + 1, part.begin() + k + 6);
    return by_tag;
  }
} // namespace

int main(int argc, char **argv)
{
  dealii::Utilities::MPI::MPI_InitFinalize mpi(argc, argv, 1);
  try
    {
      const int  ranks = dealii::Utilities::MPI::n_mpi_processes(MPI_COMM_WORLD);
      const bool root  = dealii::Utilities::MPI::this_mpi_process(MPI_COMM_WORLD) == 0;
      expect(throws_naming([]() { parameters_from_string(scene("  set Shape function = test wide linear")); },
                           "does not match"),
             "a test member is not in Solver/Shape function before register_test_shapes()");
      register_test_shapes();
      const Parameters p = parameters_from_string(scene("  set Shape function = test wide linear"));
      expect(p.shape_function == ShapeFunction::test_wide_linear && safe_distance_outside_home_cell(p.shape_function) == 0.5,
             "registered, it is a Shape function, with its own migration margin (half a cell)");
      expect(throws_naming([]() {
               parameters_from_string(scene("  set Shape function = test wide linear\n  set GIMP domain update = U"));
             }, "needs Shape function = GIMP or cubic B-spline GIMP"),
             "GIMP domain update is refused for it, naming the members whose point_domain takes it");
      expect(parameters_from_string(scene("  set Shape function = test wide linear\n  set Velocity transfer = APIC")).apic,
             "APIC is accepted (linear weights: B D^-1 is the gradient form)");

      const std::map<long, std::vector<double>> linear = run("linear"), wide = run("test wide linear");
      if (root)
        {
          double worst[5] = {}, scale[5] = {0.01, 0.01, 1, 1, 1}; // h for positions, 1 m/s, 1
          double moved = 0;
          bool   same_points = linear.size() == wide.size() && linear.size() > 0;
          for (const auto &[tag, a] : linear)
            {
              const auto b = wide.find(tag);
              if (b == wide.end())
                {
                  same_points = false;
                  break;
                }
              for (int k = 0; k < 5; ++k)
                worst[k] = std::max(worst[k], std::abs(a[k] - b->second[k]) / scale[k]);
              moved = std::max(moved, a[0] - std::round(a[0] / 2.5e-3) * 2.5e-3);
            }
          std::printf("test wide linear against linear, %d rank(s), %zu points, 40 steps: largest difference "
                      "x %.2e h, y %.2e h, v_x %.2e m/s, v_y %.2e m/s, plastic strain %.2e\n",
                      ranks, linear.size(), worst[0], worst[1], worst[2], worst[3], worst[4]);
          expect(same_points, "both runs end with the same points");
          for (int k = 0; k < 5; ++k)
            expect(worst[k] < 1e-10, std::string("the member's run equals the linear run to round-off (") +
                                       (k == 0 ? "x" : k == 1 ? "y" : k == 2 ? "v_x" : k == 3 ? "v_y" : "eps_p") + ")",
                   worst[k], 1e-10);
        }
    }
  catch (const std::exception &e)
    {
      std::printf("exception: %s\n", e.what());
      return 1;
    }
  return mpm_test::finish("test_shape_family");
}
