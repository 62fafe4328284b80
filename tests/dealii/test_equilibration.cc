// The equilibration before t = 0 (Initial state/Equilibrate, Simulator::setup):
//  - a 2D elastic slope (H = 4 m, face 1:2) with the geostatic stress of a level surface, which
//    is not in equilibrium under a slope, stepped with no damping for twenty elastic wave
//    transits: without the equilibration its points move at a good fraction of sqrt(g H); with
//    it they stay at rest (largest speed below 1e-3 sqrt(g H), largest stress change below 1e-3
//    rho g H, the targets of the FEM hand-over), time and step still 0 after setup;
//  - the report: as many damped steps as it took, the stresses' change of the same order as
//    the error of the geostatic state, the speed at rest below the tolerance;
//  - refused with a message naming the entry: a gravity ramp, a damping of 1, a state that
//    does not come to rest within the maximum number of steps.
#include "../core/check.h"

#include <mpm/dealii/parameters.h>
#include <mpm/dealii/simulator.h>

#include <deal.II/base/mpi.h>

#include <cmath>
#include <cstdio>
#include <string>

using namespace mpm;
using mpm_test::check;
using mpm_test::check_below;
using mpm_test::throws_naming;

namespace
{
  constexpr double H = 4, rho = 2000, g = 9.81;

  std::string scene(const std::string &initial_state)
  {
    return R"(
      set Dimension = 2
      subsection Grid
        set Lower corner = 0, 0
        set Upper corner = 14, 6
        set Cell size    = 0.25
      end
      subsection Boundary conditions
        set x min = free-slip
        set x max = free-slip
        set y min = no-slip
        set y max = free
      end
      subsection Solver
        set End time      = 1.0
        set Local damping = 0
      end
      subsection Materials
        set Names = soil
      end
      subsection Material soil
        set Model = linear elastic
        subsection linear elastic
          set Young's modulus = 10e6
          set Poisson's ratio = 0.3
        end
      end
      subsection Material points
        set Number of bodies = 1
        subsection Body 1
          set Shape          = polygon
          set Polygon vertices = 0, 0; 12, 0; 12, 2; 8, 2; 4, 4; 0, 4
          set Density        = 2000
          set Material       = soil
          set Initial stress = geostatic
          set K0             = 0.4286
        end
      end
      subsection Output
        set Output interval   = 0
        set Write particles   = false
        set Write grid fields = false
      end
      subsection Initial state
    )" + initial_state +
           "\nend\n";
  }

  struct AtRest
  {
    double speed = 0, stress_change = 0; // / sqrt(g H), / (rho g H)
  };

  // Runs the scene to its end time (1 s, twenty transits of H at the P-wave speed 82 m/s).
  AtRest run(Simulator<2> &simulator)
  {
    simulator.setup();
    const HostPoints<2, double> start = simulator.points();
    AtRest result;
    while (!simulator.finished())
      {
        simulator.advance();
        const HostPoints<2, double> now = simulator.points();
        for (int i = 0; i < now.size(); ++i)
          result.speed = std::max(result.speed, std::hypot(now.velocity[0][i], now.velocity[1][i]));
      }
    simulator.finish();
    const HostPoints<2, double> end = simulator.points();
    check(end.size() == start.size(), "the run keeps its points in their order");
    for (int i = 0; i < end.size() && i < start.size(); ++i)
      for (int c = 0; c < n_voigt; ++c)
        result.stress_change = std::max(result.stress_change, std::abs(end.stress[c][i] - start.stress[c][i]));
    result.speed /= std::sqrt(g * H);
    result.stress_change /= rho * g * H;
    return result;
  }
} // namespace

int main(int argc, char **argv)
{
  dealii::Utilities::MPI::MPI_InitFinalize mpi(argc, argv, 1);
  try
    {
      Simulator<2> raw(parameters_from_string(scene("set Equilibrate = false")), MPI_COMM_WORLD);
      const AtRest without = run(raw);
      check(raw.equilibration().steps == 0, "no equilibration where Equilibrate = false");

      Simulator<2> equilibrated(parameters_from_string(scene("set Equilibrate = true")), MPI_COMM_WORLD);
      equilibrated.setup();
      const EquilibrationReport report = equilibrated.equilibration();
      check(equilibrated.time() == 0 && equilibrated.step() == 0, "the equilibration leaves time and step at 0");
      Simulator<2> again(parameters_from_string(scene("set Equilibrate = true")), MPI_COMM_WORLD);
      const AtRest with = run(again);

      std::printf("geostatic state under a 1:2 slope, 20 transits with no damping:\n"
                  "  as given:     largest speed %.3e sqrt(g H), largest stress change %.3e rho g H\n"
                  "  equilibrated: largest speed %.3e sqrt(g H), largest stress change %.3e rho g H\n"
                  "  equilibration: %ld damped steps, stresses changed by up to %.3e rho g H (r.m.s. %.3e), "
                  "speed at rest %.3e sqrt(g H)\n",
                  without.speed, without.stress_change, with.speed, with.stress_change, report.steps,
                  report.max_stress_change / (rho * g * H), report.rms_stress_change / (rho * g * H),
                  report.final_speed / report.reference_speed);

      check(without.speed > 1e-2, "the geostatic state of a level surface moves under a slope", without.speed, 1e-2);
      check_below(with.speed, 1e-3, "equilibrated, the slope stays at rest: largest speed / sqrt(g H)");
      check_below(with.stress_change, 1e-3, "equilibrated, the slope stays at rest: largest stress change / rho g H");
      check(report.steps > 0 && std::abs(report.reference_speed - std::sqrt(g * H)) < 1e-2 * std::sqrt(g * H),
            "the report counts the damped steps and takes sqrt(g H) of the body's height as its speed");
      check_below(report.final_speed / report.reference_speed, 1e-6, "the points end below the tolerance's speed");
      // The geostatic state misses the slope's equilibrium by a good part of rho g H near the
      // face; the equilibration removes that, as the undamped run would oscillate about it.
      check(report.max_stress_change > 1e-2 * rho * g * H && report.max_stress_change < rho * g * H,
            "the equilibration changes the stresses by the geostatic state's error (1e-2..1 rho g H)",
            report.max_stress_change / (rho * g * H));

      check(throws_naming(
              []() {
                parameters_from_string(scene("set Equilibrate = true") +
                                       "subsection Solver\n set Gravity ramp time = 0.5\nend\n");
              },
              "Initial state/Equilibrate"),
            "a gravity ramp with the equilibration is refused, naming the entry");
      check(throws_naming([]() { parameters_from_string(scene("set Equilibrate = true\nset Equilibration damping = 1")); },
                          "Initial state/Equilibration damping"),
            "an equilibration damping of 1 is refused, naming the entry");
      check(throws_naming(
              []() {
                Simulator<2> simulator(
                  parameters_from_string(scene("set Equilibrate = true\nset Equilibration maximum steps = 20")),
                  MPI_COMM_WORLD);
                simulator.setup();
              },
              "Initial state/Equilibration maximum steps"),
            "a state not at rest within the maximum number of steps stops the run, naming the entry");
    }
  catch (const std::exception &e)
    {
      std::printf("exception: %s\n", e.what());
      return 1;
    }
  return mpm_test::finish("test_equilibration");
}
