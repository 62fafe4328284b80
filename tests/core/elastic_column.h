// V1 of ../shared/BENCHMARKS.md: elastic column under ramped self-weight (plane strain,
// one cell wide, rollers on the base and the sides). Analytic Cauchy stress in terms of
// the initial height: sigma_yy(y0) = -rho g (l0 - y0), whatever the constitutive law.
#pragma once

#include <mpm/core/backend/cpu_backend.h>
#include <mpm/core/point_generation.h>
#include <mpm/core/step.h>

#include <cmath>
#include <vector>

namespace mpm_test
{
  struct ColumnResult
  {
    double error;    // sum_p |sigma_yy - exact| V0_p / (rho g l0 V0)
    double top;      // final height of the highest point
    long   n_steps;
    int    n_points;
  };

  template <typename Shape, typename Backend = mpm::CpuBackend>
  ColumnResult run_elastic_column(const int n_cells, const double cfl = 0.5,
                                  const mpm::DomainUpdate domain_update = mpm::DomainUpdate::stretch,
                                  const double flip_fraction = 0.0, const double damping = 0.0,
                                  const bool smooth_ramp = false,
                                  const double duration_in_ramps = 2.0)
  {
    using namespace mpm;
    const double l0 = 10, E = 1e4, rho = 80, g = 9.81;
    const double c      = std::sqrt(E / rho);
    const double t_ramp = 40 * l0 / c, t_end = duration_in_ramps * t_ramp;
    const double h      = l0 / n_cells;

    HostGrid<2, double> grid;
    const double        lower[2] = {0, 0};
    const int           cells[2] = {1, n_cells};
    grid.make_dense(lower, h, cells);
    for (long n = 0; n < long(grid.lattice_to_node.size()); ++n)
      {
        int idx[2];
        grid.lattice_coordinates(n, idx);
        grid.fixed_components[n] = 1u; // rollers on both sides: every node is on a side
        if (idx[1] == 0)
          grid.fixed_components[n] |= 2u; // roller on the base
      }

    HostPoints<2, double>      points;
    BodyDescription<2, double> body{2, rho, {0, 0}, 0};
    const double               hi[2] = {h, l0};
    add_points(points, grid, lower, hi, body, [](const double *) { return true; });
    const std::vector<double> y0 = points.position[1];

    MaterialParameters<double> material;
    material.model                  = MaterialModel::linear_elastic;
    material.elastic.youngs_modulus = E;
    material.elastic.poissons_ratio = 0;

    StepSettings<2, double> s;
    s.scheme         = UpdateScheme::musl;
    s.gravity[0]     = 0;
    s.damping        = damping;
    s.flip_fraction  = flip_fraction;
    s.domain_update  = domain_update;
    s.mass_tolerance = 1e-12 * points.mass[0];

    Backend  backend;
    auto     gv = grid.view();
    auto     pv = points.view();
    double   t = 0, max_speed = 0;
    long     steps = 0;
    while (t < t_end - 1e-12 * t_end)
      {
        double dt = cfl * h / (c + max_speed);
        if (t + dt > t_end)
          dt = t_end - t;
        const double ramp = std::min(1.0, t / t_ramp);
        s.gravity[1]      = -g * (smooth_ramp ? 0.5 * (1 - std::cos(M_PI * ramp)) : ramp);
        const StepReduction<double> r = explicit_step<2, Shape>(backend, gv, pv, &material, s, dt);
        max_speed                   = r.max_speed;
        t += dt;
        ++steps;
      }

    ColumnResult result{0, 0, steps, points.size()};
    double       V0 = 0;
    for (int i = 0; i < points.size(); ++i)
      {
        const double exact = -rho * g * (l0 - y0[i]);
        result.error += std::abs(points.stress[1][i] - exact) * points.initial_volume[i];
        V0 += points.initial_volume[i];
        result.top = std::max(result.top, points.position[1][i]);
      }
    result.error /= rho * g * l0 * V0;
    return result;
  }
} // namespace mpm_test
