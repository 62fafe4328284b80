// FP32 against FP64 on the CUDA backend, one number per scene (issue 5, item 4):
//   V1: elastic column under ramped self-weight (tests/core/elastic_column.h's scene,
//       32 cells, cpGIMP), to 2 t_ramp: the V1 error norm in each precision, and the
//       largest difference of sigma_yy per point over rho g l0;
//   V3: 2D granular collapse (prm/granular_collapse_2d.prm: 0.2 m x 0.1 m column,
//       h = 2.5 mm, 2x2 points per cell, Drucker-Prager phi = 19.8 deg, c = psi = 0,
//       geostatic K0 = 0.4286, no-slip base, roller walls, no damping), 1 s: toe
//       (largest x + l_x), height (largest y + l_y), and the RMS and largest
//       difference of the final point positions, in mm.
// The same initial points (made in double) run in both precisions; FP32 results are
// compared after conversion to double. Usage: fp_accuracy [--v3-cells-per-m N]
#include "../tests/gpu/gpu_targets.h"

#include <mpm/core/point_generation.h>
#include <mpm/core/precision.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <type_traits>
#include <vector>

namespace
{
  using namespace mpm;

  struct Scene2D
  {
    HostGrid<2, double>        grid;
    HostPoints<2, double>      points;
    MaterialParameters<double> material;
    double                     c; // elastic wave speed
  };

  // Runs a 2D scene in precision Real on the device; gravity(t) gives g_y.
  template <typename Real, typename Gravity>
  HostPoints<2, double> run(const Scene2D &scene, const double t_end, const double cfl, const double damping,
                            const DomainUpdate domain_update, Gravity &&gravity, long &n_steps)
  {
    HostGrid<2, Real>   grid = converted<Real>(scene.grid);
    HostPoints<2, Real> points;
    convert_points(scene.points, points);
    StepSettings<2, Real> s;
    s.scheme         = UpdateScheme::musl;
    s.gravity[0]     = 0;
    s.damping        = Real(damping);
    s.flip_fraction  = 1;
    s.domain_update  = domain_update;
    s.mass_tolerance = Real(1e-12 * scene.points.mass[0]);
    mpm_test::CudaTarget<2, Real> target(grid, points, {converted<Real>(scene.material)});
    auto   gv = target.grid();
    auto   pv = target.points();
    double time = 0, max_speed = 0;
    n_steps     = 0;
    while (time < t_end * (1 - 1e-12))
      {
        const double dt = std::min(cfl * scene.grid.h / (scene.c + max_speed), t_end - time);
        s.gravity[1]    = Real(gravity(time));
        max_speed = double(explicit_step<2, GimpShape>(target.backend, gv, pv, target.material_table(), s, Real(dt))
                             .max_speed);
        time += dt;
        ++n_steps;
      }
    target.finish();
    HostPoints<2, double> result;
    convert_points(points, result);
    return result;
  }

  void v1()
  {
    const double l0 = 10, E = 1e4, rho = 80, g = 9.81, c = std::sqrt(E / rho), t_ramp = 40 * l0 / c;
    const int    n_cells = 32;
    const double h       = l0 / n_cells;
    Scene2D      scene;
    const double lower[2] = {0, 0};
    const int    cells[2] = {1, n_cells};
    scene.grid.make_dense(lower, h, cells);
    for (long n = 0; n < long(scene.grid.lattice_to_node.size()); ++n)
      {
        int idx[2];
        scene.grid.lattice_coordinates(n, idx);
        scene.grid.fixed_components[n] = 1u | (idx[1] == 0 ? 2u : 0u);
      }
    BodyDescription<2, double> body{2, rho, {0, 0}, 0};
    const double               hi[2] = {h, l0};
    add_points(scene.points, scene.grid, lower, hi, body, [](const double *) { return true; });
    scene.material                        = MaterialParameters<double>{};
    scene.material.model                  = MaterialModel::linear_elastic;
    scene.material.elastic.youngs_modulus = E;
    scene.material.elastic.poissons_ratio = 0;
    scene.c                               = c;
    const std::vector<double> y0          = scene.points.position[1];
    auto gravity = [&](const double t) { return -g * std::min(1.0, t / t_ramp); };
    long n64, n32;
    const auto p64 = run<double>(scene, 2 * t_ramp, 0.5, 0.05, DomainUpdate::stretch, gravity, n64);
    const auto p32 = run<float>(scene, 2 * t_ramp, 0.5, 0.05, DomainUpdate::stretch, gravity, n32);
    auto error = [&](const HostPoints<2, double> &p) {
      double e = 0, V0 = 0;
      for (int i = 0; i < p.size(); ++i)
        {
          e += std::abs(p.stress[1][i] + rho * g * (l0 - y0[i])) * p.initial_volume[i];
          V0 += p.initial_volume[i];
        }
      return e / (rho * g * l0 * V0);
    };
    double ds = 0, dy = 0;
    for (int i = 0; i < p64.size(); ++i)
      {
        ds = std::max(ds, std::abs(p64.stress[1][i] - p32.stress[1][i]) / (rho * g * l0));
        dy = std::max(dy, std::abs(p64.position[1][i] - p32.position[1][i]) / h);
      }
    std::printf("V1 column, 32 cells, cpGIMP, %ld/%ld steps: V1 error FP64 %.6e, FP32 %.6e, difference %.2e; "
                "max |sigma_yy32 - sigma_yy64| / (rho g l0) = %.2e; max |y32 - y64| / h = %.2e\n",
                n64, n32, error(p64), error(p32), std::abs(error(p32) - error(p64)), ds, dy);
  }

  void v3()
  {
    const double h = 0.0025, rho = 2650, g = 9.81, K0 = 0.4286, H = 0.1, L = 0.2;
    Scene2D      scene;
    const double lower[2] = {0, 0};
    const int    cells[2] = {int(std::lround(0.6 / h)), int(std::lround(0.12 / h))};
    scene.grid.make_dense(lower, h, cells);
    for (long n = 0; n < long(scene.grid.lattice_to_node.size()); ++n)
      {
        int idx[2];
        scene.grid.lattice_coordinates(n, idx);
        std::uint8_t mask = 0;
        if (idx[0] == 0 || idx[0] == cells[0])
          mask |= 1u; // free-slip walls
        if (idx[1] == 0)
          mask |= 3u; // no-slip base
        scene.grid.fixed_components[n] = mask;
      }
    BodyDescription<2, double> body{2, rho, {0, 0}, 0};
    const double               hi[2] = {L, H};
    add_points(scene.points, scene.grid, lower, hi, body, [](const double *) { return true; });
    for (int i = 0; i < scene.points.size(); ++i)
      {
        const double syy         = -rho * g * (H - scene.points.position[1][i]);
        scene.points.stress[1][i] = syy;
        scene.points.stress[0][i] = scene.points.stress[2][i] = K0 * syy;
      }
    auto &m                                      = scene.material;
    m                                            = MaterialParameters<double>{};
    m.model                                      = MaterialModel::drucker_prager;
    m.elastic.youngs_modulus                     = 0.84e6;
    m.elastic.poissons_ratio                     = 0.3;
    m.drucker_prager.strength.friction_angle     = 19.8 * M_PI / 180;
    m.drucker_prager.strength.residual_friction_angle = 19.8 * M_PI / 180;
    scene.c = std::sqrt(m.elastic.p_wave_modulus() / rho);
    auto gravity = [&](double) { return -g; };
    long n64, n32;
    const auto p64 = run<double>(scene, 1.0, 0.5, 0.0, DomainUpdate::det_F, gravity, n64);
    const auto p32 = run<float>(scene, 1.0, 0.5, 0.0, DomainUpdate::det_F, gravity, n32);
    auto toe_height = [](const HostPoints<2, double> &p, double &toe, double &height) {
      toe = height = 0;
      for (int i = 0; i < p.size(); ++i)
        if (p.material[i] >= 0)
          {
            toe    = std::max(toe, p.position[0][i] + p.domain_half_length[0][i]);
            height = std::max(height, p.position[1][i] + p.domain_half_length[1][i]);
          }
    };
    double toe64, h64, toe32, h32;
    toe_height(p64, toe64, h64);
    toe_height(p32, toe32, h32);
    double sum2 = 0, dmax = 0;
    int    removed_mismatch = 0;
    for (int i = 0; i < p64.size(); ++i)
      {
        if ((p64.material[i] < 0) != (p32.material[i] < 0))
          ++removed_mismatch;
        const double dx = p64.position[0][i] - p32.position[0][i], dy = p64.position[1][i] - p32.position[1][i];
        sum2 += dx * dx + dy * dy;
        dmax = std::max(dmax, std::sqrt(dx * dx + dy * dy));
      }
    std::printf("V3 2D collapse, h = 2.5 mm, %d points, DP, 1 s, %ld/%ld steps: toe FP64 %.2f mm, FP32 %.2f mm; "
                "height FP64 %.2f mm, FP32 %.2f mm; position difference RMS %.3f mm, max %.3f mm; "
                "removed-status mismatches %d\n",
                p64.size(), n64, n32, 1e3 * toe64, 1e3 * toe32, 1e3 * h64, 1e3 * h32,
                1e3 * std::sqrt(sum2 / p64.size()), 1e3 * dmax, removed_mismatch);
  }
} // namespace

int main()
{
  try
    {
      if (!mpm_test::cuda_device_present("fp_accuracy"))
        return mpm_test::skip_code;
      v1();
      v3();
    }
  catch (const std::exception &e)
    {
      std::fprintf(stderr, "fp_accuracy: %s\n", e.what());
      return 1;
    }
  return 0;
}
