// V1 of ../shared/BENCHMARKS.md: elastic column under ramped self-weight (plane strain,
// one cell wide, rollers on the base and the sides). Analytic Cauchy stress in terms of
// the initial height: sigma_yy(y0) = -rho g (l0 - y0), whatever the constitutive law.
// Templated on the Target (targets.h), so the CPU test and its GPU twin share it.
#pragma once

#include "targets.h"

#include <mpm/core/point_generation.h>
#include <mpm/core/step.h>

#include <algorithm>
#include <cmath>
#include <vector>

namespace mpm_test
{
  struct ColumnSetup
  {
    int               n_cells;
    double            cfl           = 0.5;
    mpm::DomainUpdate domain_update = mpm::DomainUpdate::stretch;
    double            flip_fraction = 1.0;
    double            damping       = 0.05;
    long              max_steps     = -1; // < 0: run to 2 t_ramp
    double            youngs_modulus = 1e4; // V1's; 1e6 compresses by 0.78%, not 78%
  };

  struct ColumnResult
  {
    double error = 0; // sum_p |sigma_yy - exact| V0_p / (rho g l0 V0)
    double top   = 0; // final height of the highest point
    double time  = 0;
    long   n_steps = 0;
  };

  // Runs the column; `points` receives the final state. `initial`, if given, replaces the
  // generated points (same scene, e.g. reordered).
  template <typename Shape, template <int, typename> class Target = CpuTarget>
  ColumnResult elastic_column(const ColumnSetup &setup, mpm::HostPoints<2, double> &points,
                              const mpm::HostPoints<2, double> *initial = nullptr)
  {
    using namespace mpm;
    const double l0 = 10, E = setup.youngs_modulus, rho = 80, g = 9.81;
    const double c = std::sqrt(E / rho), t_ramp = 40 * l0 / c, t_end = 2 * t_ramp, h = l0 / setup.n_cells;

    HostGrid<2, double> grid;
    const double        lower[2] = {0, 0};
    const int           cells[2] = {1, setup.n_cells};
    grid.make_dense(lower, h, cells);
    for (long n = 0; n < long(grid.lattice_to_node.size()); ++n)
      {
        int idx[2];
        grid.lattice_coordinates(n, idx);
        // rollers on both sides (every node is on a side) and on the base
        grid.fixed_components[n] = 1u | (idx[1] == 0 ? 2u : 0u);
      }

    points = HostPoints<2, double>();
    BodyDescription<2, double> body{2, rho, {0, 0}, 0};
    const double               hi[2] = {h, l0};
    add_points(points, grid, lower, hi, body, [](const double *) { return true; });
    if constexpr (Shape::tracks_corners) // CPDI2q's corners, as offsets from the rectangle: zero
      points.set_n_state_variables(8);
    if (initial != nullptr)
      points = *initial;
    const std::vector<double> y0 = points.position[1];

    MaterialParameters<double> material{};
    material.model                  = MaterialModel::linear_elastic;
    material.elastic.youngs_modulus = E;
    material.elastic.poissons_ratio = 0;

    StepSettings<2, double> s;
    s.scheme         = UpdateScheme::musl;
    s.gravity[0]     = 0;
    s.damping        = setup.damping;
    s.flip_fraction  = setup.flip_fraction;
    s.domain_update  = setup.domain_update;
    s.mass_tolerance = 1e-12 * points.mass[0];
    if constexpr (Shape::tracks_corners)
      s.corner_state_variable = 0;

    ColumnResult r;
    {
      Target<2, double> target(grid, points, {material});
      auto              gv        = target.grid();
      double            max_speed = 0;
      while (r.time < t_end - 1e-12 * t_end && (setup.max_steps < 0 || r.n_steps < setup.max_steps))
        {
          const double dt = std::min(setup.cfl * h / (c + max_speed), t_end - r.time);
          s.gravity[1]    = -g * std::min(1.0, r.time / t_ramp);
          const auto pv   = target.template points_at_step<Shape>(r.n_steps);
          max_speed = explicit_step<2, Shape>(target.backend, gv, pv, target.material_table(), s, dt).max_speed;
          r.time += dt;
          ++r.n_steps;
        }
      target.finish();
    }

    double V0 = 0;
    for (int i = 0; i < points.size(); ++i)
      {
        r.error += std::abs(points.stress[1][i] + rho * g * (l0 - y0[i])) * points.initial_volume[i];
        V0 += points.initial_volume[i];
        r.top = std::max(r.top, points.position[1][i]);
      }
    r.error /= rho * g * l0 * V0;
    return r;
  }
} // namespace mpm_test
