// CPU micro-benchmark of the step (core only, no deal.II, no output): the V3 2D scene of
// prm/granular_collapse_2d.prm (12,800 points, h = 2.5 mm, GIMP, MUSL, Drucker-Prager,
// FLIP 0.99, pressure averaging, geostatic start, adaptive dt at CFL 0.5). Not a ctest.
//   bench_v3_step [steps=2000] [positions file to write, - for none] [positions file to compare
//                 with, - for none] [threads, 0 = TBB's default]
// Prints user CPU s, wall s, point-updates/s and, with a reference file, the largest
// position difference (scaled by h) and velocity difference against it.
#include "scene_helpers.h"

#include <mpm/core/backend/cpu_backend.h>
#include <mpm/core/step.h>

#ifdef MPM_WITH_TBB
#  include <tbb/global_control.h>
#endif

#include <sys/resource.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <vector>

using namespace mpm;

namespace
{
  double user_cpu_seconds()
  {
    rusage u;
    getrusage(RUSAGE_SELF, &u);
    return u.ru_utime.tv_sec + 1e-6 * u.ru_utime.tv_usec;
  }
  // Counters of the CPU backend's slab grouping, where it has them.
  template <typename B>
  auto grouping_built(const B &b) -> decltype(b.n_built)
  {
    return b.n_built;
  }
  long grouping_built(...) { return -1; }
  template <typename B>
  auto grouping_kept(const B &b) -> decltype(b.n_reused)
  {
    return b.n_reused;
  }
  long grouping_kept(...) { return -1; }
} // namespace

int main(int argc, char **argv)
{
  const int steps   = argc > 1 ? std::atoi(argv[1]) : 2000;
  const int threads = argc > 4 ? std::atoi(argv[4]) : 0;
#ifdef MPM_WITH_TBB
  tbb::global_control limit(tbb::global_control::max_allowed_parallelism,
                            threads > 0 ? threads : tbb::global_control::active_value(
                                                      tbb::global_control::max_allowed_parallelism));
#endif
  constexpr int dim = 2;
  const double  h = 0.0025, rho = 2650, g_y = -9.81, K0 = 0.4286, H = 0.1;

  HostGrid<dim, double> grid;
  const double lower[2] = {0, 0};
  const int    cells[2] = {240, 48};
  grid.make_dense(lower, h, cells);
  for (int j = 0; j <= cells[1]; ++j)
    for (int i = 0; i <= cells[0]; ++i)
      {
        const int n = i + (cells[0] + 1) * j;
        if (i == 0 || i == cells[0])
          grid.fixed_components[n] |= 1u; // free-slip walls
        if (j == 0)
          grid.fixed_components[n] |= 3u; // no-slip base
      }

  HostPoints<dim, double> points;
  const int nx = 160, ny = 80; // 2 x 2 points per cell in 0.2 m x 0.1 m
  points.resize(nx * ny);
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i)
      {
        const int    p = i + nx * j;
        const double x = (i + 0.5) * h / 2, y = (j + 0.5) * h / 2;
        points.position[0][p] = x;
        points.position[1][p] = y;
        for (int d = 0; d < dim; ++d)
          {
            points.velocity[d][p]                   = 0;
            points.domain_half_length[d][p]         = points.initial_domain_half_length[d][p] = 0.25 * h;
          }
        points.volume[p] = points.initial_volume[p] = 0.25 * h * h;
        points.mass[p]                               = rho * points.volume[p];
        for (int c = 0; c < n_voigt; ++c)
          points.stress[c][p] = points.strain[c][p] = 0;
        const double syy      = rho * g_y * (H - y);
        points.stress[1][p]   = syy;
        points.stress[0][p]   = points.stress[2][p] = K0 * syy;
        points.plastic_strain[p] = 0;
        points.material_field[p] = 0;
        points.material[p]       = 0;
      }

  MaterialParameters<double> dp;
  dp.model                                   = MaterialModel::drucker_prager;
  dp.elastic.youngs_modulus                  = 0.84e6;
  dp.elastic.poissons_ratio                  = 0.3;
  dp.drucker_prager.strength.cohesion        = 0;
  dp.drucker_prager.strength.friction_angle  = 19.8 * M_PI / 180;
  dp.drucker_prager.strength.residual_friction_angle = 19.8 * M_PI / 180;
  dp.drucker_prager.strength.dilatancy_angle = 0;

  StepSettings<dim, double> s;
  s.scheme             = UpdateScheme::musl;
  s.gravity[0]         = 0;
  s.gravity[1]         = g_y;
  s.damping            = 0;
  s.flip_fraction      = 0.99;
  s.domain_update      = DomainUpdate::none;
  s.mass_tolerance     = 1e-12 * points.mass[0];
  s.pressure_averaging = true;

  const double nu = 0.3, E = 0.84e6;
  const double c_el = std::sqrt(E * (1 - nu) / ((1 + nu) * (1 - 2 * nu)) / rho);

  CpuBackend backend;
  double     max_speed = 0, time = 0;
  const auto   wall0 = std::chrono::steady_clock::now();
  const double cpu0  = user_cpu_seconds();
  for (int step = 0; step < steps; ++step)
    {
      const double dt = 0.5 * h / (c_el + max_speed);
      const auto   r  = explicit_step<dim, GimpShape>(backend, grid.view(), points.view(), &dp, s, dt);
      max_speed       = r.max_speed;
      time += dt;
    }
  const double cpu  = user_cpu_seconds() - cpu0;
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
  int          removed = 0;
  for (int i = 0; i < points.size(); ++i)
    removed += points.material[i] < 0;
  std::printf("grouping built %ld, kept %ld times\n", grouping_built(backend), grouping_kept(backend));
  std::printf("steps %d  t %.6f s  removed %d  user CPU %.3f s  wall %.3f s  CPU ns/update %.1f  "
              "point-updates/s (wall) %.3g\n",
              steps, time, removed, cpu, wall, 1e9 * cpu / (double(steps) * points.size()),
              double(steps) * points.size() / wall);

  const int n = points.size();
  if (argc > 2 && argv[2][0] != '-')
    {
      std::ofstream out(argv[2], std::ios::binary);
      for (int d = 0; d < dim; ++d)
        {
          out.write(reinterpret_cast<const char *>(points.position[d].data()), n * sizeof(double));
          out.write(reinterpret_cast<const char *>(points.velocity[d].data()), n * sizeof(double));
        }
    }
  if (argc > 3 && argv[3][0] != '-')
    {
      std::ifstream        in(argv[3], std::ios::binary);
      std::vector<double>  x(n), v(n);
      double               dx = 0, dv = 0, vmax = 0;
      for (int d = 0; d < dim; ++d)
        {
          in.read(reinterpret_cast<char *>(x.data()), n * sizeof(double));
          in.read(reinterpret_cast<char *>(v.data()), n * sizeof(double));
          for (int i = 0; i < n; ++i)
            {
              dx   = std::max(dx, std::fabs(x[i] - points.position[d][i]) / h);
              dv   = std::max(dv, std::fabs(v[i] - points.velocity[d][i]));
              vmax = std::max(vmax, std::fabs(v[i]));
            }
        }
      std::printf("against %s: max |dx|/h %.3g  max |dv| %.3g (max |v| %.3g)\n", argv[3], dx, dv, vmax);
    }
  return 0;
}
