// APIC (StepSettings::affine_state_variable, step.h) on the CPU backend:
// - an affine velocity field v = A x + b, with C_p = A, survives a step unchanged: every point's
//   velocity and affine matrix come back to round-off (the transfers are exact for affine fields
//   with any weights that reproduce linear fields), for linear, GIMP and the quadratic B-spline,
//   MUSL and USL, in 2D and 3D;
// - a free elastic block spun by a quarter turn keeps its angular momentum under APIC (as FLIP
//   does) where PIC loses much of it.
#include "check.h"
#include "spinning_block.h"

#include <mpm/core/backend/cpu_backend.h>
#include <mpm/core/point_generation.h>
#include <mpm/core/step.h>

#include <cmath>
#include <cstdio>
#include <random>
#include <vector>

using namespace mpm;

namespace
{
  // Largest error of v_p and C_p against the affine field after one step (relative to |A| h + |b|).
  template <int dim, typename Shape>
  double affine_round_trip(const UpdateScheme scheme)
  {
    const double h = 0.1;
    HostGrid<dim, double> grid;
    double                lower[dim], lo[dim], hi[dim];
    int                   cells[dim];
    for (int d = 0; d < dim; ++d)
      {
        lower[d] = 0;
        cells[d] = 12;
        lo[d]    = 0.3 + 0.01 * d; // not aligned with the cells
        hi[d]    = 0.83;
      }
    grid.make_dense(lower, h, cells);
    std::fill(grid.fixed_components.begin(), grid.fixed_components.end(), 0u);
    HostPoints<dim, double>      points;
    BodyDescription<dim, double> body{2, 1000, {}, 0};
    add_points(points, grid, lo, hi, body, [](const double *) { return true; });
    points.set_n_state_variables(dim * dim);

    std::mt19937                           rng(7);
    std::uniform_real_distribution<double> u(-1, 1);
    double                                 A[dim][dim], b[dim], scale = 0;
    for (int a = 0; a < dim; ++a)
      {
        b[a] = u(rng);
        scale += std::abs(b[a]);
        for (int c = 0; c < dim; ++c)
          {
            A[a][c] = u(rng);
            scale += std::abs(A[a][c]) * h;
          }
      }
    std::vector<std::vector<double>> x0(dim);
    for (int i = 0; i < points.size(); ++i)
      for (int a = 0; a < dim; ++a)
        {
          double v = b[a];
          for (int c = 0; c < dim; ++c)
            {
              v += A[a][c] * points.position[c][i];
              points.state_variables[a * dim + c][i] = A[a][c];
            }
          points.velocity[a][i] = v;
        }
    for (int a = 0; a < dim; ++a)
      x0[a] = points.position[a];

    MaterialParameters<double> material{};
    material.model                  = MaterialModel::linear_elastic;
    material.elastic.youngs_modulus = 1e6;
    material.elastic.poissons_ratio = 0.3;
    StepSettings<dim, double> s{};
    s.scheme                = scheme;
    s.damping               = 0;
    s.flip_fraction         = 0;
    s.affine_state_variable = 0;
    s.domain_update         = DomainUpdate::none;
    s.mass_tolerance        = 1e-12 * points.mass[0];
    CpuBackend backend;
    explicit_step<dim, Shape>(backend, grid.view(), points.view(), &material, s, 1e-6);

    double worst = 0;
    for (int i = 0; i < points.size(); ++i)
      for (int a = 0; a < dim; ++a)
        {
          double v = b[a];
          for (int c = 0; c < dim; ++c)
            {
              v += A[a][c] * x0[c][i];
              worst = std::max(worst, std::abs(points.state_variables[a * dim + c][i] - A[a][c]) * h / scale);
            }
          worst = std::max(worst, std::abs(points.velocity[a][i] - v) / scale);
        }
    return worst;
  }

  template <int dim>
  void round_trips()
  {
    for (const UpdateScheme scheme : {UpdateScheme::musl, UpdateScheme::usl})
      {
        const char  *name = scheme == UpdateScheme::musl ? "MUSL" : "USL";
        const double e_linear = affine_round_trip<dim, LinearShape>(scheme);
        const double e_gimp   = affine_round_trip<dim, GimpShape>(scheme);
        const double e_spline = affine_round_trip<dim, QuadraticBSplineShape>(scheme);
        std::printf("%dD %s, an affine field through one APIC step: linear %.1e, GIMP %.1e, B-spline %.1e\n", dim,
                    name, e_linear, e_gimp, e_spline);
        mpm_test::check_below(e_linear, 1e-9, "APIC keeps an affine field, linear");
        mpm_test::check_below(e_gimp, 1e-9, "APIC keeps an affine field, GIMP");
        mpm_test::check_below(e_spline, 1e-9, "APIC keeps an affine field, quadratic B-spline");
      }
  }
} // namespace

int main()
{
  round_trips<2>();
  round_trips<3>();

  HostPoints<2, double> points;
  const mpm_test::SpinResult flip =
    mpm_test::spinning_block<2, GimpShape>(DomainUpdate::none, points, M_PI / 2, -1, nullptr, {1, false});
  const mpm_test::SpinResult pic =
    mpm_test::spinning_block<2, GimpShape>(DomainUpdate::none, points, M_PI / 2, -1, nullptr, {0, false});
  const mpm_test::SpinResult apic =
    mpm_test::spinning_block<2, GimpShape>(DomainUpdate::none, points, M_PI / 2, -1, nullptr, {0, true});
  std::printf("spinning block, a quarter turn (uGIMP): angular momentum kept FLIP %.4f, PIC %.4f, APIC %.4f; "
              "turned %.4f / %.4f / %.4f rad; kinetic energy %.4f / %.4f / %.4f\n",
              flip.momentum_ratio, pic.momentum_ratio, apic.momentum_ratio, flip.angle, pic.angle, apic.angle,
              flip.energy_ratio, pic.energy_ratio, apic.energy_ratio);
  mpm_test::check_below(std::abs(apic.momentum_ratio - 1), 0.01, "APIC keeps the spin's angular momentum");
  mpm_test::check(pic.momentum_ratio < 0.9, "PIC loses it (the contrast that makes the test able to fail)",
                  pic.momentum_ratio, 0.9);
  return mpm_test::finish("test_apic");
}
