// P2G and G2P conserve mass and linear momentum to round-off on random point sets;
// a rigid translation is reproduced exactly; a free-flying deforming block keeps
// its mass and momentum (no boundaries, no gravity, no damping).
#include <mpm/core/backend/cpu_backend.h>
#include <mpm/core/point_generation.h>

#include "check.h"
#include "scene_helpers.h"

#include <string>

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

template <int dim, typename Shape>
void random_transfer(const char *name, const UpdateScheme scheme, std::mt19937 &rng)
{
  HostGrid<dim, double> grid;
  const double          lower[3] = {0, 0, 0};
  const int             cells[3] = {12, 10, 9};
  grid.make_dense(lower, 0.1, cells);
  HostPoints<dim, double> points;
  mpm_test::random_points(points, grid, 3000, rng);
  auto g = grid.view();
  auto p = points.view();
  CpuBackend backend;
  const auto s = mpm_test::quiet_settings<dim>(scheme);
  const MaterialParameters<double> material = mpm_test::elastic(1e4, 0.3);

  double m0, P0[dim];
  totals(points, m0, P0);

  // P2G alone: nodal totals equal point totals.
  stages::reset_grid(backend, g, true);
  stages::particles_to_grid<dim, Shape>(backend, g, p, s, true, true);
  double mg = 0, Pg[dim] = {}, Fg[dim] = {};
  for (int n = 0; n < g.n_nodes; ++n)
    {
      mg += g.mass[n];
      for (int d = 0; d < dim; ++d)
        {
          Pg[d] += g.momentum[d][n];
          Fg[d] += g.force[d][n];
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
  const std::string what = std::string(name) + " " + std::to_string(dim) + "D";
  mpm_test::check_below(std::abs(mg - m0) / m0, 1e-14, (what + ": P2G mass").c_str());
  mpm_test::check_below(err_p, 1e-14, (what + ": P2G momentum").c_str());
  mpm_test::check_below(err_f, 1e-14, (what + ": internal forces sum to zero").c_str());

  // Whole steps (P2G, grid update, G2P, remap, kinematics, stress): totals unchanged.
  for (int step = 0; step < 5; ++step)
    explicit_step<dim, Shape>(backend, g, p, &material, s, 1e-4);
  double m1, P1[dim];
  totals(points, m1, P1);
  double err = 0;
  for (int d = 0; d < dim; ++d)
    err = std::max(err, std::abs(P1[d] - P0[d]) / scale);
  std::printf("%s: P2G mass %.1e, momentum %.1e, force sum %.1e; 5 steps: mass %.1e, momentum %.1e\n",
              what.c_str(), std::abs(mg - m0) / m0, err_p, err_f, std::abs(m1 - m0) / m0, err);
  mpm_test::check_below(std::abs(m1 - m0) / m0, 1e-14, (what + ": step conserves mass").c_str());
  mpm_test::check_below(err, 1e-13, (what + ": step conserves momentum").c_str());
}

template <int dim, typename Shape>
void rigid_translation(const char *name)
{
  HostGrid<dim, double> grid;
  const double          lower[3] = {0, 0, 0};
  const int             cells[3] = {20, 12, 12};
  grid.make_dense(lower, 0.05, cells);
  HostPoints<dim, double>       points;
  BodyDescription<dim, double>  body{2, 1000.0, {0.7, -0.3}, 0};
  if (dim == 3)
    body.velocity[dim - 1] = 0.2;
  const double lo[3] = {0.2, 0.2, 0.2}, hi[3] = {0.4, 0.4, 0.4};
  add_points(points, grid, lo, hi, body, [](const double *) { return true; });
  const HostPoints<dim, double> initial = points;
  auto       g = grid.view();
  auto       p = points.view();
  CpuBackend backend;
  const MaterialParameters<double> material = mpm_test::elastic(1e6, 0.3);
  for (const UpdateScheme scheme : {UpdateScheme::musl, UpdateScheme::usl, UpdateScheme::usf})
    {
      points   = initial;
      p        = points.view();
      auto s   = mpm_test::quiet_settings<dim>(scheme);
      double t = 0;
      const double dt = 2e-4;
      for (int step = 0; step < 500; ++step, t += dt)
        explicit_step<dim, Shape>(backend, g, p, &material, s, dt);
      double err_x = 0, err_v = 0, err_s = 0;
      for (int i = 0; i < points.size(); ++i)
        {
          for (int d = 0; d < dim; ++d)
            {
              err_x = std::max(err_x, std::abs(points.position[d][i] - initial.position[d][i] - body.velocity[d] * t));
              err_v = std::max(err_v, std::abs(points.velocity[d][i] - body.velocity[d]));
            }
          for (int c = 0; c < n_voigt; ++c)
            err_s = std::max(err_s, std::abs(points.stress[c][i]));
        }
      std::printf("%s %dD scheme %d rigid translation: |dx| %.1e m, |dv| %.1e m/s, |sigma| %.1e Pa\n", name, dim,
                  int(scheme), err_x, err_v, err_s);
      mpm_test::check_below(err_x, 1e-13, "rigid translation: positions");
      mpm_test::check_below(err_v, 1e-11, "rigid translation: velocities (round-off of 500 steps)");
      mpm_test::check_below(err_s, 1e-6, "rigid translation: no stress (1e-12 of E)");
    }
}

// An elastic block, pre-stressed and spinning, flies freely for 400 steps.
template <int dim>
void free_flight()
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
  const MaterialParameters<double> material = mpm_test::elastic(1e6, 0.3);
  auto s = mpm_test::quiet_settings<dim>(UpdateScheme::musl);
  s.flip_fraction = 0.9;
  auto       g = grid.view();
  auto       p = points.view();
  CpuBackend backend;
  double     m0, P0[dim];
  totals(points, m0, P0);
  const double x_first = points.position[0][0];
  const double c  = std::sqrt(material.elastic.p_wave_modulus() / 1000.0);
  const double dt = 0.3 * grid.h / (c + 3);
  for (int step = 0; step < 400; ++step)
    explicit_step<dim, GimpShape>(backend, g, p, &material, s, dt);
  double m1, P1[dim], err = 0;
  totals(points, m1, P1);
  for (int d = 0; d < dim; ++d)
    err = std::max(err, std::abs(P1[d] - P0[d]) / (m0 * 0.3));
  const double moved = std::abs(points.position[0][0] - x_first);
  std::printf("free flight %dD: %d points, mass drift %.1e, momentum drift %.1e (relative to m |v|)\n", dim,
              points.size(), std::abs(m1 - m0) / m0, err);
  mpm_test::check(moved > 0.02, "free flight: the block moved");
  mpm_test::check_below(std::abs(m1 - m0) / m0, 1e-14, "free flight: mass");
  mpm_test::check_below(err, 1e-12, "free flight: momentum");
}

int main()
{
  std::mt19937 rng(7);
  for (const UpdateScheme scheme : {UpdateScheme::musl, UpdateScheme::usl, UpdateScheme::usf})
    {
      random_transfer<2, LinearShape>("linear", scheme, rng);
      random_transfer<3, LinearShape>("linear", scheme, rng);
      random_transfer<2, GimpShape>("GIMP", scheme, rng);
      random_transfer<3, GimpShape>("GIMP", scheme, rng);
    }
  rigid_translation<2, LinearShape>("linear");
  rigid_translation<3, LinearShape>("linear");
  rigid_translation<2, GimpShape>("GIMP");
  rigid_translation<3, GimpShape>("GIMP");
  free_flight<2>();
  free_flight<3>();
  return mpm_test::finish("test_transfer_conservation");
}
