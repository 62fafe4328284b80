// StepSettings::hold_points (step.h), the step of the equilibration of an initial state:
// the points keep position, F, volume and GIMP domain, and only their stresses follow the grid.
//
// Scene: an elastic column 1 m high and 2 m wide on a fixed base (plane strain, nu = 0, E = 100
// MPa, rho = 1000, g = 10, h = 0.125 m, 2x2 points per cell), released from zero stress.
// 1. One step from the same state, held and not: the stresses are the same to the last bit (the
//    constitutive update comes before the points move); held, the kinematic fields are unchanged
//    to the last bit, not held, the points have moved.
// 2. Held steps with local damping D = 0.8 and PIC until the largest speed is below 1e-12 m/s:
//    the column ends in the geostatic state, sigma_xx = 0 (nu = 0) and sigma_yy = -rho g (H - y)
//    as the grid resolves it: the points of a cell (2x2, their domains inside it) see the same
//    nodes with one gradient, strain alike and carry one stress, that of the cell's centre (the
//    nodes balance only a cell's mean stress, so the exact geostatic state balances too).
//    Asked to 1e-8 rho g H, the points still where they started.
#include "check.h"
#include "scene_helpers.h"

#include <mpm/core/backend/cpu_backend.h>
#include <mpm/core/point_generation.h>
#include <mpm/core/step.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

using namespace mpm;
using mpm_test::check;
using mpm_test::check_below;

namespace
{
  constexpr double h = 0.125, rho = 1000, E = 1e8, g = 10, H = 1;

  struct Column
  {
    HostGrid<2, double>                     grid;
    HostPoints<2, double>                   points;
    std::vector<MaterialParameters<double>> materials{mpm_test::elastic(E, 0)};
    StepSettings<2, double>                 settings = mpm_test::quiet_settings<2>(UpdateScheme::musl);

    Column()
    {
      const double lower[2] = {0, 0};
      const int    cells[2] = {32, 12};
      grid.make_dense(lower, h, cells);
      for (long n = 0; n < long(grid.lattice_to_node.size()); ++n)
        {
          int idx[2];
          grid.lattice_coordinates(n, idx);
          grid.fixed_components[n] = idx[1] == 0 ? 3u : 0u; // fixed base
        }
      BodyDescription<2, double> body{2, rho, {0, 0}, 0};
      const double               lo[2] = {8 * h, 0}, hi[2] = {8 * h + 2, H};
      add_points(points, grid, lo, hi, body, [](const double *) { return true; });
      settings.gravity[1]     = -g;
      settings.mass_tolerance = 1e-12 * points.mass[0];
    }

    double step(const bool hold, const double dt)
    {
      settings.hold_points = hold;
      CpuBackend backend;
      return explicit_step<2, GimpShape>(backend, grid.view(), points.view(), materials.data(), settings, dt)
        .max_speed;
    }
  };

  void test_one_step()
  {
    Column       held, moved;
    const double dt = 0.5 * h / std::sqrt(E / rho);
    held.step(true, dt);
    moved.step(false, dt);
    const HostPoints<2, double> &a = held.points, &b = moved.points, start = Column().points;
    bool same_stress = true, kept = true, displaced = false;
    for (int i = 0; i < a.size(); ++i)
      {
        for (int c = 0; c < n_voigt; ++c)
          same_stress = same_stress && a.stress[c][i] == b.stress[c][i];
        for (int d = 0; d < 2; ++d)
          {
            kept = kept && a.position[d][i] == start.position[d][i] &&
                   a.domain_half_length[d][i] == start.domain_half_length[d][i];
            displaced = displaced || b.position[d][i] != start.position[d][i];
          }
        for (int k = 0; k < 4; ++k)
          kept = kept && a.deformation_gradient[k][i] == start.deformation_gradient[k][i];
        kept = kept && a.volume[i] == start.volume[i];
      }
    check(same_stress, "one step held and not held: the same stresses to the last bit");
    check(kept, "held: position, F, volume and GIMP domain unchanged to the last bit");
    check(displaced, "not held: the points moved (the comparison can fail)");
  }

  void test_relaxation()
  {
    Column column;
    column.settings.damping       = 0.8;
    column.settings.flip_fraction = 0;
    const HostPoints<2, double> start = column.points;
    const double                dt    = 0.5 * h / std::sqrt(E / rho);
    double                      speed = 1;
    long                        steps = 0;
    for (; steps < 200000 && (steps < 10 || speed > 1e-12); ++steps)
      speed = column.step(true, dt);
    double error = 0, moved = 0;
    const HostPoints<2, double> &p = column.points;
    for (int i = 0; i < p.size(); ++i)
      {
        // The points of a cell (their GIMP domains inside it) see its nodes only, with one
        // gradient: they strain alike and carry one stress, the geostatic one of the cell's centre.
        const double depth = H - (std::floor(p.position[1][i] / h) + 0.5) * h;
        error = std::max({error, std::fabs(p.stress[1][i] + rho * g * depth), std::fabs(p.stress[0][i]),
                          std::fabs(p.stress[3][i])});
        for (int d = 0; d < 2; ++d)
          moved = std::max(moved, std::fabs(p.position[d][i] - start.position[d][i]));
      }
    std::printf("held relaxation from zero stress: %ld steps to a largest speed of %.1e m/s; largest stress error "
                "%.2e rho g H against the geostatic state; points moved %.1e m\n",
                steps, speed, error / (rho * g * H), moved);
    check_below(speed, 1e-12, "the held, damped steps come to rest");
    check_below(error / (rho * g * H), 1e-8, "at rest, the column holds the geostatic stress (sigma_yy, sigma_xx = "
                                             "sigma_xy = 0) to 1e-8 rho g H");
    check(moved == 0, "the points have not moved");
  }
} // namespace

int main()
{
  test_one_step();
  test_relaxation();
  return mpm_test::finish("test_hold_points");
}
