// The manufactured solution of the method study (manufactured_solution.h):
// - its body force is the one the motion needs: d2u/dt2 - Div P / rho0 with Div P and the
//   acceleration taken by central differences of the closed-form stress and displacement, for
//   both elastic laws, at points spread over the square and the period;
// - cpGIMP with the U domain update converges at second order under it (Jaumann and Hencky:
//   errors and orders at 8, 16, 32 cells), and with the step in float it reaches double's errors
//   (its round-off, 1e-7 of a coordinate, lies far below the discretisation's 1e-2);
// - a body force asked of points without the state variables to hold it is refused.
#include "check.h"
#include "manufactured_solution.h"

#include <cmath>
#include <cstdio>

namespace
{
  using mpm_test::AxisAlignedMotion;

  // First Piola-Kirchhoff P_dd of the closed-form stress (F diagonal: P_dd = J sigma_dd / F_dd).
  double piola(const AxisAlignedMotion &m, const double X[2], const double t, const int d)
  {
    double sigma[3];
    m.stress(X, t, sigma);
    const double a = m.stretch(X[0], t), b = m.stretch(X[1], t);
    return a * b * sigma[d] / (d == 0 ? a : b);
  }

  // Largest |g - (u_tt - Div P / rho0)| over a grid of points and times, relative to |u_tt| scale.
  double body_force_mismatch(const AxisAlignedMotion &m)
  {
    const double dX = 1e-5 * m.length, dt = 1e-5 * m.period;
    double       worst = 0, scale = 0;
    for (int k = 1; k < 8; ++k)
      for (int i = 1; i < 9; ++i)
        for (int j = 1; j < 9; ++j)
          {
            const double t = k * m.period / 8, X[2] = {0.1 * i * m.length + 0.013, 0.1 * j * m.length - 0.007};
            double       g[2];
            m.body_force(X, t, g);
            for (int d = 0; d < 2; ++d)
              {
                double Xp[2] = {X[0], X[1]}, Xm[2] = {X[0], X[1]};
                Xp[d] += dX;
                Xm[d] -= dX;
                const double div_P = (piola(m, Xp, t, d) - piola(m, Xm, t, d)) / (2 * dX);
                const double u_tt =
                  (m.displacement(X[d], t + dt) - 2 * m.displacement(X[d], t) + m.displacement(X[d], t - dt)) /
                  (dt * dt);
                worst = std::max(worst, std::abs(g[d] - (u_tt - div_P / m.density)));
                scale = std::max(scale, std::abs(div_P / m.density));
              }
          }
    return worst / scale;
  }

  // Returns the displacement error at 32 cells.
  template <typename Real = double>
  double check_convergence(const char *key, const double finest_limit)
  {
    AxisAlignedMotion motion;
    const auto        method = mpm_test::mms_method(key);
    motion.law               = method.law;
    double last              = 0;
    for (const int n : {8, 16, 32})
      {
        const auto r = mpm_test::run_manufactured_solution<Real>(motion, method, n);
        std::printf("%-16s %s %3d cells: displacement error %.6e, stress error %.3e, %ld steps\n", key,
                    sizeof(Real) == 4 ? "FP32" : "FP64", n, r.displacement_error, r.stress_error, r.n_steps);
        mpm_test::check(r.stable, "the run stays finite and keeps every point");
        if (last > 0)
          {
            const double order = std::log2(last / r.displacement_error);
            std::printf("%-16s order %.2f\n", key, order);
            mpm_test::check(order >= 1.8, "second-order convergence of the displacement", order, 1.8);
          }
        last = r.displacement_error;
      }
    mpm_test::check_below(last, finest_limit, "displacement error at 32 cells");
    return last;
  }
} // namespace

int main()
{
  for (const auto law : {mpm::ElasticLaw::jaumann_rate, mpm::ElasticLaw::hencky})
    {
      AxisAlignedMotion m;
      m.law                = law;
      const double mismatch = body_force_mismatch(m);
      std::printf("body force against differences (%s): %.2e\n",
                  law == mpm::ElasticLaw::hencky ? "Hencky" : "Jaumann", mismatch);
      mpm_test::check_below(mismatch, 1e-5, "body force = u_tt - Div P / rho0");
    }

  {
    mpm::HostGrid<2, double> grid;
    const double             lower[2] = {0, 0};
    const int                cells[2] = {4, 4};
    grid.make_dense(lower, 0.25, cells);
    mpm::HostPoints<2, double> points;
    mpm::add_points(points, grid, lower, lower, mpm::BodyDescription<2, double>{2, 1000, {0, 0}, 0},
                    [](const double *) { return true; });
    auto s                      = mpm::StepSettings<2, double>();
    s.scheme                    = mpm::UpdateScheme::musl;
    s.body_force_state_variable = 0;
    mpm::CpuBackend backend;
    const auto      material = mpm::MaterialParameters<double>{};
    mpm_test::check(mpm_test::throws_naming(
                      [&]() { mpm::explicit_step<2, mpm::GimpShape>(backend, grid.view(), points.view(), &material, s, 1e-3); },
                      "body force needs dim state variables"),
                    "a body force without its state variables is refused");
  }

  const double in_double = check_convergence("cpgimp_u", 1.5e-2);
  const double in_float  = check_convergence<float>("cpgimp_u", 1.5e-2);
  mpm_test::check_below(std::abs(in_float - in_double) / in_double, 1e-3,
                        "FP32's displacement error at 32 cells against FP64's (relative)");
  check_convergence("cpgimp_u_hencky", 1.5e-2);
  check_convergence("cpdi", 1.5e-2);
  check_convergence("cpdi2q", 1.5e-2);
  return mpm_test::finish("test_manufactured_solution");
}
