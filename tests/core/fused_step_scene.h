// P1 (benchmarks/p1_scene.h, Drucker-Prager) stepped with or without the fused step
// (FusedTransfer, step.h), on any Target (targets.h), so that the CPU test and its GPU twin
// compare the same runs.
#pragma once

#include "../../benchmarks/p1_scene.h"

#include <mpm/core/host_storage.h>
#include <mpm/core/step.h>

#include <algorithm>
#include <cmath>
#include <type_traits>
#include <vector>

namespace mpm_test
{
  struct FusedRun
  {
    int                 n_cells_y = 2; // 10,024 points
    long                n_steps   = 150;
    bool                fused     = false;
    mpm::UpdateScheme   scheme    = mpm::UpdateScheme::musl;
    bool                drucker_prager = true;
    double              damping        = mpm_bench::P1::damping;
  };

  // The steps at P1's adaptive time step and ramped gravity; a fused step carries the next
  // step's P2G with the gravity of the next step's time. Returns the time reached.
  template <template <int, typename> class Target, typename Shape = mpm::GimpShape>
  double p1_fused_or_not(const FusedRun &run, mpm::HostPoints<3, double> &points)
  {
    using namespace mpm;
    using mpm_bench::P1;
    HostGrid<3, double>                     grid;
    std::vector<MaterialParameters<double>> materials;
    mpm_bench::make_p1(run.n_cells_y, grid, points, materials, run.drucker_prager);
    StepSettings<3, double> s = mpm_bench::p1_settings<double>();
    s.scheme                  = run.scheme;
    s.damping                 = run.damping;
    if constexpr (!std::is_same_v<Shape, GimpShape> && !std::is_same_v<Shape, CubicBSplineGimpShape>)
      s.domain_update = DomainUpdate::none; // as p1_benchmark: only the GIMP shapes have domains to update
    const double            c = mpm_bench::p1_wave_speed();
    Target<3, double>       target(grid, points, materials);
    const auto              gv = target.grid();
    FusedTransfer<3, double> fused;
    double                  t = 0, max_speed = 0;
    for (long step = 0; step < run.n_steps; ++step)
      {
        const double dt = P1::cfl * P1::h / (c + max_speed);
        mpm_bench::p1_gravity(s, t);
        if (run.fused)
          {
            StepSettings<3, double> next = s;
            mpm_bench::p1_gravity(next, t + dt);
            fused.carry_next = step + 1 < run.n_steps;
            for (int d = 0; d < 3; ++d)
              fused.next_gravity[d] = next.gravity[d];
          }
        const auto pv = target.template points_at_step<Shape>(step);
        max_speed     = explicit_step<3, Shape>(target.backend, gv, pv, target.material_table(), s, dt,
                                            NoGridExchange(), nullptr, run.fused ? &fused : nullptr)
                      .max_speed;
        t += dt;
      }
    target.finish();
    return t;
  }

  // Largest difference over the points: positions in cells, velocities and stresses
  // relative to their largest magnitude; removed points must match.
  inline double largest_difference(const mpm::HostPoints<3, double> &a, const mpm::HostPoints<3, double> &b)
  {
    double v_scale = 1e-300, s_scale = 1e-300, worst = 0;
    for (int i = 0; i < a.size(); ++i)
      {
        for (int d = 0; d < 3; ++d)
          v_scale = std::max(v_scale, std::abs(a.velocity[d][i]));
        for (int c = 0; c < mpm::n_voigt; ++c)
          s_scale = std::max(s_scale, std::abs(a.stress[c][i]));
      }
    for (int i = 0; i < a.size(); ++i)
      {
        if ((a.material[i] < 0) != (b.material[i] < 0))
          return 1;
        for (int d = 0; d < 3; ++d)
          {
            worst = std::max(worst, std::abs(a.position[d][i] - b.position[d][i]) / mpm_bench::P1::h);
            worst = std::max(worst, std::abs(a.velocity[d][i] - b.velocity[d][i]) / v_scale);
          }
        for (int c = 0; c < mpm::n_voigt; ++c)
          worst = std::max(worst, std::abs(a.stress[c][i] - b.stress[c][i]) / s_scale);
        worst = std::max(worst, std::abs(a.volume[i] - b.volume[i]) / a.initial_volume[i]);
        worst = std::max(worst, std::abs(a.plastic_strain[i] - b.plastic_strain[i]));
      }
    return worst;
  }
} // namespace mpm_test
