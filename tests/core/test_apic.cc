// The affine transfers (StepSettings::affine_state_variable and affine_matrix, step.h) on the CPU
// backend, TPIC (C = sum v_i grad N_i^T) and APIC (C = B D^-1, the B-splines' constant D):
// - an affine velocity field v = A x + b, with C_p = A, survives a step unchanged: every point's
//   velocity and affine matrix come back to round-off (TPIC: linear, GIMP, the quadratic and cubic
//   B-splines; APIC: linear and the B-splines, away from the grid's faces), MUSL and USL, 2D and 3D;
// - at the grid's faces APIC's C is A with each column scaled by a factor in [0, 1] (the folded
//   weights' second moment is below the constant D), never amplified;
// - a free elastic block spun by a quarter turn keeps its angular momentum under TPIC (uGIMP) and
//   APIC (quadratic B-spline), as FLIP does, where PIC loses much of it;
// - APIC with GIMP (no constant D) is refused, naming the shape functions it takes.
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
  // at_faces: the points fill the whole grid, and the result is the largest amount by which a
  // |C_ab| exceeds |A_ab| (relative to |A| h + |b|) instead of the error.
  template <int dim, typename Shape>
  double affine_round_trip(const UpdateScheme scheme, const AffineMatrix form = AffineMatrix::velocity_gradient,
                           const bool at_faces = false)
  {
    const double h = 0.1;
    HostGrid<dim, double> grid;
    double                lower[dim], lo[dim], hi[dim];
    int                   cells[dim];
    for (int d = 0; d < dim; ++d)
      {
        lower[d] = 0;
        cells[d] = 12;
        lo[d]    = at_faces ? 0 : 0.3 + 0.01 * d; // not aligned with the cells
        hi[d]    = at_faces ? 1.2 : 0.83;
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
    s.affine_matrix         = form;
    s.domain_update         = DomainUpdate::none;
    s.mass_tolerance        = 1e-12 * points.mass[0];
    CpuBackend backend;
    explicit_step<dim, Shape>(backend, grid.view(), points.view(), &material, s, 1e-6);

    double worst = 0;
    if (at_faces)
      {
        for (int i = 0; i < points.size(); ++i)
          for (int a = 0; a < dim; ++a)
            for (int c = 0; c < dim; ++c)
              worst = std::max(worst, (std::abs(points.state_variables[a * dim + c][i]) - std::abs(A[a][c])) * h /
                                        scale);
        return worst;
      }
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
        const double e_cubic  = affine_round_trip<dim, CubicBSplineShape>(scheme);
        std::printf("%dD %s, an affine field through one TPIC step: linear %.1e, GIMP %.1e, B-spline %.1e, "
                    "cubic %.1e\n",
                    dim, name, e_linear, e_gimp, e_spline, e_cubic);
        mpm_test::check_below(e_linear, 1e-9, "TPIC keeps an affine field, linear");
        mpm_test::check_below(e_gimp, 1e-9, "TPIC keeps an affine field, GIMP");
        mpm_test::check_below(e_spline, 1e-9, "TPIC keeps an affine field, quadratic B-spline");
        mpm_test::check_below(e_cubic, 1e-9, "TPIC keeps an affine field, cubic B-spline");

        const auto   apic       = AffineMatrix::b_d_inverse;
        const double a_linear   = affine_round_trip<dim, LinearShape>(scheme, apic);
        const double a_spline   = affine_round_trip<dim, QuadraticBSplineShape>(scheme, apic);
        const double a_cubic    = affine_round_trip<dim, CubicBSplineShape>(scheme, apic);
        const double f_spline   = affine_round_trip<dim, QuadraticBSplineShape>(scheme, apic, true);
        const double f_cubic    = affine_round_trip<dim, CubicBSplineShape>(scheme, apic, true);
        std::printf("%dD %s, an affine field through one APIC step: linear %.1e, B-spline %.1e, cubic %.1e; "
                    "at the faces |C| - |A| at most %.1e / %.1e\n",
                    dim, name, a_linear, a_spline, a_cubic, f_spline, f_cubic);
        mpm_test::check_below(a_linear, 1e-9, "APIC keeps an affine field, linear");
        mpm_test::check_below(a_spline, 1e-9, "APIC keeps an affine field, quadratic B-spline");
        mpm_test::check_below(a_cubic, 1e-9, "APIC keeps an affine field, cubic B-spline");
        mpm_test::check_below(f_spline, 1e-9, "APIC's C at the faces is not larger than A, quadratic B-spline");
        mpm_test::check_below(f_cubic, 1e-9, "APIC's C at the faces is not larger than A, cubic B-spline");
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
  const mpm_test::SpinResult tpic =
    mpm_test::spinning_block<2, GimpShape>(DomainUpdate::none, points, M_PI / 2, -1, nullptr, {0, true});
  std::printf("spinning block, a quarter turn (uGIMP): angular momentum kept FLIP %.4f, PIC %.4f, TPIC %.4f; "
              "turned %.4f / %.4f / %.4f rad; kinetic energy %.4f / %.4f / %.4f\n",
              flip.momentum_ratio, pic.momentum_ratio, tpic.momentum_ratio, flip.angle, pic.angle, tpic.angle,
              flip.energy_ratio, pic.energy_ratio, tpic.energy_ratio);
  mpm_test::check_below(std::abs(tpic.momentum_ratio - 1), 0.01, "TPIC keeps the spin's angular momentum");
  mpm_test::check(pic.momentum_ratio < 0.9, "PIC loses it (the contrast that makes the test able to fail)",
                  pic.momentum_ratio, 0.9);

  const mpm_test::SpinResult spline_pic = mpm_test::spinning_block<2, QuadraticBSplineShape>(
    DomainUpdate::none, points, M_PI / 2, -1, nullptr, {0, false});
  const mpm_test::SpinResult spline_apic = mpm_test::spinning_block<2, QuadraticBSplineShape>(
    DomainUpdate::none, points, M_PI / 2, -1, nullptr, {0, true, AffineMatrix::b_d_inverse});
  std::printf("spinning block, a quarter turn (quadratic B-spline): angular momentum kept PIC %.4f, APIC %.4f; "
              "turned %.4f / %.4f rad\n",
              spline_pic.momentum_ratio, spline_apic.momentum_ratio, spline_pic.angle, spline_apic.angle);
  mpm_test::check_below(std::abs(spline_apic.momentum_ratio - 1), 0.01, "APIC keeps the spin's angular momentum");
  mpm_test::check(spline_pic.momentum_ratio < 0.9, "PIC loses it with the B-spline too", spline_pic.momentum_ratio,
                  0.9);

  {
    HostGrid<2, double> grid;
    const double        lower[2] = {0, 0};
    const int           cells[2] = {4, 4};
    grid.make_dense(lower, 0.25, cells);
    HostPoints<2, double> none;
    none.set_n_state_variables(4);
    StepSettings<2, double> s{};
    s.flip_fraction         = 0; // APIC's (the check after it is the one tested)
    s.affine_state_variable = 0;
    s.affine_matrix         = AffineMatrix::b_d_inverse;
    CpuBackend backend;
    const MaterialParameters<double> material{};
    mpm_test::check(mpm_test::throws_naming(
                      [&]() { explicit_step<2, GimpShape>(backend, grid.view(), none.view(), &material, s, 1e-3); },
                      "APIC (B D^-1) needs a shape function with a constant D_p"),
                    "APIC with GIMP is refused");
  }
  return mpm_test::finish("test_apic");
}
