// P2G and G2P conserve mass and linear momentum to round-off on random point sets; a
// rigid translation is reproduced exactly; a free-flying, pre-stressed, spinning block
// keeps its mass and momentum (no boundaries, no gravity, no damping). On any Target:
// test_transfer_conservation.cc runs it on the CPU, tests/gpu/ on the device (atomics
// only reorder sums, which these limits do not see). A short form (fewer steps, the same
// checks, the free flight's drift test scaled to its length) is for the sanitizers, under
// which every launch costs orders of magnitude more: test_gpu_transfer_conservation --short.
#pragma once

#include "check.h"
#include "scene_helpers.h"
#include "targets.h"

#include <mpm/core/point_generation.h>

#include <string>

namespace mpm_test
{
using namespace mpm;

template <int dim>
void totals(const HostPoints<dim, double> &p, double &mass, double momentum[dim])
{
  mass = 0;
  for (int d = 0; d < dim; ++d)
    momentum[d] = 0;
  for (int i = 0; i < p.size(); ++i)
    if (p.material[i] >= 0)
      {
        mass += p.mass[i];
        for (int d = 0; d < dim; ++d)
          momentum[d] += p.mass[i] * p.velocity[d][i];
      }
}

template <template <int, typename> class Target, int dim, typename Shape>
void random_transfer(const char *name, const UpdateScheme scheme, std::mt19937 &rng)
{
  HostGrid<dim, double> grid;
  const double          lower[3] = {0, 0, 0};
  const int             cells[3] = {12, 10, 9};
  grid.make_dense(lower, 0.1, cells);
  HostPoints<dim, double> points;
  random_points(points, grid, 3000, rng);
  const auto s = quiet_settings<dim>(scheme);
  double     m0, P0[dim];
  totals(points, m0, P0);

  Target<dim, double> target(grid, points, {elastic(1e4, 0.3)});
  auto g = target.grid();
  auto p = target.points();
  stages::reset_grid(target.backend, g, true);
  stages::particles_to_grid<dim, Shape>(target.backend, g, p, s, true, true);
  target.finish();
  double mg = 0, Pg[dim] = {}, Fg[dim] = {};
  for (int n = 0; n < g.n_nodes; ++n)
    {
      mg += grid.mass[n];
      for (int d = 0; d < dim; ++d)
        {
          Pg[d] += grid.momentum[d][n];
          Fg[d] += grid.force[d][n];
        }
    }
  double scale = 0;
  for (int i = 0; i < points.size(); ++i)
    scale += points.mass[i];
  double err_p = 0, err_f = 0;
  for (int d = 0; d < dim; ++d)
    {
      err_p = std::max(err_p, std::abs(Pg[d] - P0[d]) / scale);
      err_f = std::max(err_f, std::abs(Fg[d]) / (100 * 0.02 * points.size() / 0.1));
    }
  const std::string what = std::string(Target<dim, double>::name) + " " + name + " " + std::to_string(dim) + "D scheme " + std::to_string(int(scheme));
  check_below(std::abs(mg - m0) / m0, 1e-14, (what + ": P2G mass").c_str());
  check_below(err_p, 1e-14, (what + ": P2G momentum").c_str());
  check_below(err_f, 1e-14, (what + ": internal forces sum to zero").c_str());

  for (int step = 0; step < 5; ++step)
    explicit_step<dim, Shape>(target.backend, g, p, target.material_table(), s, 1e-4);
  target.finish();
  double m1, P1[dim];
  totals(points, m1, P1);
  double err = 0;
  for (int d = 0; d < dim; ++d)
    err = std::max(err, std::abs(P1[d] - P0[d]) / scale);
  std::printf("%s: P2G mass %.1e, momentum %.1e, force sum %.1e; 5 steps: mass %.1e, momentum %.1e\n", what.c_str(),
              std::abs(mg - m0) / m0, err_p, err_f, std::abs(m1 - m0) / m0, err);
  check_below(std::abs(m1 - m0) / m0, 1e-14, (what + ": step conserves mass").c_str());
  check_below(err, 1e-13, (what + ": step conserves momentum").c_str());
}

template <template <int, typename> class Target, int dim, typename Shape>
void rigid_translation(const char *name, const int n)
{
  HostGrid<dim, double> grid;
  const double          lower[3] = {0, 0, 0};
  const int             cells[3] = {20, 12, 12};
  grid.make_dense(lower, 0.05, cells);
  HostPoints<dim, double>      initial;
  BodyDescription<dim, double> body{2, 1000.0, {0.7, -0.3}, 0};
  if (dim == 3)
    body.velocity[dim - 1] = 0.2;
  const double lo[3] = {0.2, 0.2, 0.2}, hi[3] = {0.4, 0.4, 0.4};
  add_points(initial, grid, lo, hi, body, [](const double *) { return true; });
  for (const UpdateScheme scheme : {UpdateScheme::musl, UpdateScheme::usl, UpdateScheme::usf})
    {
      HostPoints<dim, double> points = initial;
      auto                    s      = quiet_settings<dim>(scheme);
      const double            dt     = 2e-4;
      {
        Target<dim, double> target(grid, points, {elastic(1e6, 0.3)});
        auto g = target.grid();
        auto p = target.points();
        for (int step = 0; step < n; ++step)
          explicit_step<dim, Shape>(target.backend, g, p, target.material_table(), s, dt);
        target.finish();
      }
      double err_x = 0, err_v = 0, err_s = 0;
      for (int i = 0; i < points.size(); ++i)
        {
          for (int d = 0; d < dim; ++d)
            {
              err_x = std::max(err_x, std::abs(points.position[d][i] - initial.position[d][i] - body.velocity[d] * n * dt));
              err_v = std::max(err_v, std::abs(points.velocity[d][i] - body.velocity[d]));
            }
          for (int c = 0; c < n_voigt; ++c)
            err_s = std::max(err_s, std::abs(points.stress[c][i]));
        }
      std::printf("%s %s %dD scheme %d rigid translation: |dx| %.1e m, |dv| %.1e m/s, |sigma| %.1e Pa\n", Target<dim, double>::name, name, dim,
                  int(scheme), err_x, err_v, err_s);
      check_below(err_x, 1e-13, "rigid translation: positions");
      check_below(err_v, 1e-11, "rigid translation: velocities (round-off of up to 500 steps)");
      check_below(err_s, 1e-6, "rigid translation: no stress (1e-12 of E)");
    }
}

template <template <int, typename> class Target, int dim>
void free_flight(const int n_steps)
{
  HostGrid<dim, double> grid;
  const double          lower[3] = {0, 0, 0};
  const int             cells[3] = {40, 40, 40};
  grid.make_dense(lower, 0.05, cells);
  HostPoints<dim, double>      points;
  BodyDescription<dim, double> body{2, 1000.0, {}, 0};
  const double lo[3] = {0.8, 0.8, 0.8}, hi[3] = {1.2, 1.1, 1.0};
  add_points(points, grid, lo, hi, body, [](const double *) { return true; });
  for (int i = 0; i < points.size(); ++i)
    {
      const double rx = points.position[0][i] - 1.0, ry = points.position[1][i] - 0.95;
      points.velocity[0][i] = 0.3 - 2.0 * ry;
      points.velocity[1][i] = 0.1 + 2.0 * rx;
      points.stress[0][i]   = -5e3 * (1 + rx);
    }
  const MaterialParameters<double> material = elastic(1e6, 0.3);
  auto s          = quiet_settings<dim>(UpdateScheme::musl);
  s.flip_fraction = 0.9;
  double m0, P0[dim];
  totals(points, m0, P0);
  const double x_first = points.position[0][0];
  const double c       = std::sqrt(material.elastic.p_wave_modulus() / 1000.0);
  const double dt      = 0.3 * grid.h / (c + 3);
  {
    Target<dim, double> target(grid, points, {material});
    auto g = target.grid();
    auto p = target.points();
    for (int step = 0; step < n_steps; ++step)
      explicit_step<dim, GimpShape>(target.backend, g, p, target.material_table(), s, dt);
    target.finish();
  }
  double m1, P1[dim], err = 0;
  totals(points, m1, P1);
  for (int d = 0; d < dim; ++d)
    err = std::max(err, std::abs(P1[d] - P0[d]) / (m0 * 0.3));
  std::printf("%s free flight %dD: %d points, mass drift %.1e, momentum drift %.1e (relative to m |v|)\n", Target<dim, double>::name, dim,
              points.size(), std::abs(m1 - m0) / m0, err);
  // The block drifts at 0.3 m/s and spins: the drift asked for scales with the steps run.
  check(std::abs(points.position[0][0] - x_first) > 0.02 * n_steps / 400, "free flight: the block moved");
  check_below(std::abs(m1 - m0) / m0, 1e-14, "free flight: mass");
  check_below(err, 1e-12, "free flight: momentum");
}

// short_form: 10 steps of rigid translation and free flight instead of 500 and 400.
template <template <int, typename> class Target>
void check_transfer_conservation(const bool short_form = false)
{
  const int translation_steps = short_form ? 10 : 500;
  const int flight_steps      = short_form ? 10 : 400;
  std::mt19937 rng(7);
  for (const UpdateScheme scheme : {UpdateScheme::musl, UpdateScheme::usl, UpdateScheme::usf})
    {
      random_transfer<Target, 2, LinearShape>("linear", scheme, rng);
      random_transfer<Target, 3, LinearShape>("linear", scheme, rng);
      random_transfer<Target, 2, GimpShape>("GIMP", scheme, rng);
      random_transfer<Target, 3, GimpShape>("GIMP", scheme, rng);
    }
  rigid_translation<Target, 2, LinearShape>("linear", translation_steps);
  rigid_translation<Target, 3, LinearShape>("linear", translation_steps);
  rigid_translation<Target, 2, GimpShape>("GIMP", translation_steps);
  rigid_translation<Target, 3, GimpShape>("GIMP", translation_steps);
  free_flight<Target, 2>(flight_steps);
  free_flight<Target, 3>(flight_steps);
}
} // namespace mpm_test
