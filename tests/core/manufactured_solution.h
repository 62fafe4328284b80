// A manufactured solution for the method study (issue 15): the unit square deformed along the
// axes, x_d = X_d + A sin(2 pi X_d / L) sin(omega t) for each axis d (plane strain), kept exact
// by a body force that each point carries (StepSettings::body_force_state_variable). The walls
// are rollers (u_d = 0 where X_d = 0 or L, no shear stress anywhere); the stretch reaches
// 1 +- 2 pi A / L (+-31% with the defaults), a large deformation without rotation.
//
// Without rotation (F diagonal, L diagonal, no spin) both elastic laws of the core have a
// closed form in the principal logarithmic strains eps = diag(ln a, ln b, 0), a = F_xx,
// b = F_yy:
//   Jaumann rate (hypoelastic): sigma = C : eps    (d sigma / dt = C : D, D = d eps / dt)
//   Hencky (hyperelastic):      sigma = C : eps / J, J = a b.
// The body force per unit mass is g = d2u/dt2 - Div P / rho0 with P = J sigma F^-T the first
// Piola-Kirchhoff stress; P_xx depends on X through a and on Y through b only, so
// Div P along x is dP_xx/dX:
//   Jaumann: P_xx = b sigma_xx,  dP_xx/dX = b (lambda + 2 mu) a_X / a;
//   Hencky:  P_xx = tau_xx / a, dP_xx/dX = a_X ((lambda + 2 mu) - tau_xx) / a^2.
// Axis-aligned manufactured solutions of this kind are the usual test of GIMP and CPDI
// convergence (Kamojjala et al. 2013; Sadeghirad et al. 2011).
#pragma once

#include "targets.h"

#include <mpm/core/material/material.h>
#include <mpm/core/point_generation.h>
#include <mpm/core/step.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

namespace mpm_test
{
  struct AxisAlignedMotion
  {
    double          amplitude = 0.05; // A (m)
    double          length    = 1;    // L (m): the square's side
    double          density   = 1000; // rho0 (kg/m^3)
    double          youngs_modulus = 1e7;
    double          poissons_ratio = 0.3;
    double          period         = 0.02; // 2 pi / omega (s)
    mpm::ElasticLaw law            = mpm::ElasticLaw::jaumann_rate;

    static constexpr double pi = 3.14159265358979323846;
    double omega() const { return 2 * pi / period; }
    double lame_lambda() const
    {
      return youngs_modulus * poissons_ratio / ((1 + poissons_ratio) * (1 - 2 * poissons_ratio));
    }
    double shear_modulus() const { return youngs_modulus / (2 * (1 + poissons_ratio)); }
    double p_wave_speed() const { return std::sqrt((lame_lambda() + 2 * shear_modulus()) / density); }

    // Along one axis, of the reference coordinate X_d: displacement, velocity, acceleration,
    // the stretch F_dd and its derivative dF_dd/dX_d.
    double displacement(const double X, const double t) const
    {
      return amplitude * std::sin(2 * pi * X / length) * std::sin(omega() * t);
    }
    double velocity(const double X, const double t) const
    {
      return amplitude * omega() * std::sin(2 * pi * X / length) * std::cos(omega() * t);
    }
    double acceleration(const double X, const double t) const
    {
      return -omega() * omega() * displacement(X, t);
    }
    double stretch(const double X, const double t) const
    {
      return 1 + 2 * pi * amplitude / length * std::cos(2 * pi * X / length) * std::sin(omega() * t);
    }
    double stretch_gradient(const double X, const double t) const
    {
      return -4 * pi * pi * amplitude / (length * length) * std::sin(2 * pi * X / length) * std::sin(omega() * t);
    }
    double velocity_gradient(const double X, const double t) const // dv_d/dx_d = (dF/dt) / F
    {
      return 2 * pi * amplitude * omega() / length * std::cos(2 * pi * X / length) * std::cos(omega() * t) /
             stretch(X, t);
    }

    // Cauchy stress (xx, yy, zz) at the reference point X.
    void stress(const double X[2], const double t, double sigma[3]) const
    {
      const double a = stretch(X[0], t), b = stretch(X[1], t), lambda = lame_lambda(), mu = shear_modulus();
      const double ea = std::log(a), eb = std::log(b), J = law == mpm::ElasticLaw::hencky ? a * b : 1;
      sigma[0] = (lambda * (ea + eb) + 2 * mu * ea) / J;
      sigma[1] = (lambda * (ea + eb) + 2 * mu * eb) / J;
      sigma[2] = lambda * (ea + eb) / J;
    }

    // The body force per unit mass that makes the motion exact.
    void body_force(const double X[2], const double t, double g[2]) const
    {
      const double F[2] = {stretch(X[0], t), stretch(X[1], t)}, M = lame_lambda() + 2 * shear_modulus();
      const double lnF[2] = {std::log(F[0]), std::log(F[1])};
      for (int d = 0; d < 2; ++d)
        {
          const double other = F[1 - d], F_X = stretch_gradient(X[d], t);
          const double tau   = M * lnF[d] + lame_lambda() * lnF[1 - d];
          const double div_P = law == mpm::ElasticLaw::hencky ? F_X * (M - tau) / (F[d] * F[d]) :
                                                                 other * M * F_X / F[d];
          g[d] = acceleration(X[d], t) - div_P / density;
        }
    }
  };

  // A method of the study: shape function, cpGIMP domain update, velocity transfer, elastic law.
  enum class MmsShape
  {
    linear,
    gimp,
    quadratic_bspline,
    cubic_bspline,
    cpdi,
    cpdi2q,
    cubic_bspline_gimp
  };
  struct MmsMethod
  {
    std::string       key; // scripts/validation/study.py's method name
    MmsShape          shape;
    mpm::DomainUpdate domain_update = mpm::DomainUpdate::none;
    double            flip_fraction = 0.99;
    bool              apic          = false; // an affine transfer, its matrix by `affine`
    mpm::ElasticLaw   law           = mpm::ElasticLaw::jaumann_rate;
    mpm::AffineMatrix affine        = mpm::AffineMatrix::velocity_gradient;
  };

  // The methods of scripts/validation/study.py (same keys and settings).
  inline std::vector<MmsMethod> mms_methods()
  {
    using mpm::DomainUpdate;
    return {{"gimp", MmsShape::gimp},
            {"linear", MmsShape::linear},
            {"cpgimp_det_f", MmsShape::gimp, DomainUpdate::det_F},
            {"cpgimp_f_ii", MmsShape::gimp, DomainUpdate::stretch},
            {"cpgimp_u", MmsShape::gimp, DomainUpdate::U},
            {"bspline2", MmsShape::quadratic_bspline},
            {"bspline3", MmsShape::cubic_bspline},
            {"gimp_pic", MmsShape::gimp, DomainUpdate::none, 0},
            {"gimp_flip", MmsShape::gimp, DomainUpdate::none, 1},
            {"bspline2_pic", MmsShape::quadratic_bspline, DomainUpdate::none, 0},
            {"gimp_tpic", MmsShape::gimp, DomainUpdate::none, 0, true},
            {"bspline2_tpic", MmsShape::quadratic_bspline, DomainUpdate::none, 0, true},
            {"bspline2_apic", MmsShape::quadratic_bspline, DomainUpdate::none, 0, true, mpm::ElasticLaw::jaumann_rate,
             mpm::AffineMatrix::b_d_inverse},
            {"cpgimp_u_hencky", MmsShape::gimp, DomainUpdate::U, 0.99, false, mpm::ElasticLaw::hencky},
            {"cpdi", MmsShape::cpdi},
            {"cpdi2q", MmsShape::cpdi2q},
            {"bspline3_gimp_f_ii", MmsShape::cubic_bspline_gimp, DomainUpdate::stretch}};
  }

  inline MmsMethod mms_method(const std::string &key)
  {
    for (const auto &m : mms_methods())
      if (m.key == key)
        return m;
    std::string known;
    for (const auto &m : mms_methods())
      known += (known.empty() ? "" : ", ") + m.key;
    throw std::invalid_argument("unknown method '" + key + "' (known: " + known + ")");
  }

  struct MmsResult
  {
    double displacement_error = 0; // max over the steps of the L2 (volume-weighted) error of x_p, / A
    double stress_error       = 0; // the same for sigma (xx, yy, zz), / ((lambda + 2 mu) 2 pi A / L)
    long   n_points           = 0;
    long   n_steps            = 0;
    double wall_s             = 0; // the steps alone (set-up excluded)
    bool   stable             = true; // finite, no point lost
  };

  // Runs the motion over `periods` periods on n x n cells with 2 x 2 points per cell, at CFL `cfl`
  // on the P-wave speed plus the largest point speed; the step in Real (double or float), the
  // motion, the body force and the errors in double.
  template <typename Shape, typename Real = double>
  MmsResult run_manufactured_solution_with(const AxisAlignedMotion &motion, const MmsMethod &method, const int n_cells,
                                      const double cfl = 0.2, const double periods = 1)
  {
    using namespace mpm;
    constexpr int dim = 2;
    const double  L = motion.length, h = L / n_cells, t_end = periods * motion.period;

    HostGrid<dim, Real> grid;
    const Real          lower[dim] = {0, 0}, upper[dim] = {Real(L), Real(L)};
    const int           cells[dim] = {n_cells, n_cells};
    grid.make_dense(lower, Real(h), cells);
    for (long n = 0; n < long(grid.lattice_to_node.size()); ++n)
      {
        int idx[dim];
        grid.lattice_coordinates(n, idx);
        // rollers: u_d = 0 on the walls normal to d, the tangential motion is free (no shear)
        for (int d = 0; d < dim; ++d)
          if (idx[d] == 0 || idx[d] == n_cells)
            grid.fixed_components[n] |= std::uint8_t(1u << d);
      }

    HostPoints<dim, Real> points;
    add_points(points, grid, lower, upper, BodyDescription<dim, Real>{2, Real(motion.density), {0, 0}, 0},
               [](const Real *) { return true; });
    const int                 n = points.size();
    const std::vector<double> X[dim] = {std::vector<double>(points.position[0].begin(), points.position[0].end()),
                                        std::vector<double>(points.position[1].begin(), points.position[1].end())};
    // state variables: the body force (2), then APIC's affine matrix (4), then CPDI2q's corners (8)
    const int  body_force = 0, affine = 2;
    const bool corners    = Shape::tracks_corners;
    const int  corner     = method.apic ? 6 : 2;
    points.set_n_state_variables(corner + (corners ? 8 : 0));
    for (int i = 0; i < n; ++i)
      for (int d = 0; d < dim; ++d)
        {
          points.velocity[d][i] = motion.velocity(X[d][i], 0);
          if (method.apic) // C_p = grad v, diagonal
            for (int e = 0; e < dim; ++e)
              points.state_variables[affine + d * dim + e][i] = d == e ? motion.velocity_gradient(X[d][i], 0) : 0;
        }

    MaterialParameters<Real> material{};
    material.model                  = MaterialModel::linear_elastic;
    material.elastic.youngs_modulus = motion.youngs_modulus;
    material.elastic.poissons_ratio = motion.poissons_ratio;
    material.elastic_law            = method.law;

    StepSettings<dim, Real> s;
    s.scheme                    = UpdateScheme::musl;
    s.gravity[0] = s.gravity[1] = 0;
    s.damping                   = 0;
    s.flip_fraction             = method.flip_fraction;
    s.domain_update             = method.domain_update;
    s.mass_tolerance            = 1e-12 * points.mass[0];
    s.body_force_state_variable = body_force;
    s.affine_state_variable     = method.apic ? affine : -1;
    s.affine_matrix             = method.affine;
    s.corner_state_variable     = corners ? corner : -1;

    double V0 = 0;
    for (int i = 0; i < n; ++i)
      V0 += points.initial_volume[i];
    const double stress_scale =
      (motion.lame_lambda() + 2 * motion.shear_modulus()) * 2 * AxisAlignedMotion::pi * motion.amplitude / L;

    MmsResult r;
    r.n_points = n;
    // Errors at time t of the points' state (every step: the largest of the run counts).
    auto measure = [&](const double t) {
      double ex = 0, es = 0;
      for (int i = 0; i < n; ++i)
        {
          const double Xi[dim] = {X[0][i], X[1][i]};
          double       exact[3];
          motion.stress(Xi, t, exact);
          for (int d = 0; d < dim; ++d)
            {
              const double e = points.position[d][i] - (Xi[d] + motion.displacement(Xi[d], t));
              ex += e * e * points.initial_volume[i];
            }
          for (int c = 0; c < 3; ++c)
            es += std::pow(points.stress[c][i] - exact[c], 2) * points.initial_volume[i];
        }
      ex = std::sqrt(ex / V0) / motion.amplitude;
      es = std::sqrt(es / V0) / stress_scale;
      if (!std::isfinite(ex) || !std::isfinite(es))
        r.stable = false;
      r.displacement_error = std::max(r.displacement_error, std::isfinite(ex) ? ex : HUGE_VAL);
      r.stress_error       = std::max(r.stress_error, std::isfinite(es) ? es : HUGE_VAL);
    };

    CpuTarget<dim, Real> target(grid, points, {material});
    auto                 gv        = target.grid();
    const auto           pv        = target.points();
    double                 t         = 0, max_speed = motion.amplitude * motion.omega();
    const double           c         = motion.p_wave_speed();
    const auto             started   = std::chrono::steady_clock::now();
    double                 measuring = 0;
    while (t < t_end * (1 - 1e-12) && r.stable)
      {
        const double dt = std::min(cfl * h / (c + max_speed), t_end - t);
        for (int i = 0; i < n; ++i)
          {
            const double Xi[dim] = {X[0][i], X[1][i]};
            double       g[dim];
            motion.body_force(Xi, t, g);
            for (int d = 0; d < dim; ++d)
              points.state_variables[body_force + d][i] = g[d];
          }
        max_speed = explicit_step<dim, Shape>(target.backend, gv, pv, target.material_table(), s, Real(dt)).max_speed;
        t += dt;
        ++r.n_steps;
        const auto before = std::chrono::steady_clock::now();
        measure(t);
        measuring += std::chrono::duration<double>(std::chrono::steady_clock::now() - before).count();
        if (!std::isfinite(max_speed))
          r.stable = false;
      }
    r.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count() - measuring;
    for (int i = 0; i < n && r.stable; ++i)
      r.stable = points.material[i] >= 0;
    return r;
  }

  // The same with the method's shape function chosen at run time (Real: the step's precision).
  template <typename Real = double>
  MmsResult run_manufactured_solution(const AxisAlignedMotion &motion, const MmsMethod &method, const int n_cells,
                                      const double cfl = 0.2, const double periods = 1)
  {
    switch (method.shape)
      {
        case MmsShape::linear:
          return run_manufactured_solution_with<mpm::LinearShape, Real>(motion, method, n_cells, cfl, periods);
        case MmsShape::gimp:
          return run_manufactured_solution_with<mpm::GimpShape, Real>(motion, method, n_cells, cfl, periods);
        case MmsShape::quadratic_bspline:
          return run_manufactured_solution_with<mpm::QuadraticBSplineShape, Real>(motion, method, n_cells, cfl, periods);
        case MmsShape::cubic_bspline:
          return run_manufactured_solution_with<mpm::CubicBSplineShape, Real>(motion, method, n_cells, cfl, periods);
        case MmsShape::cpdi:
          return run_manufactured_solution_with<mpm::CpdiShape, Real>(motion, method, n_cells, cfl, periods);
        case MmsShape::cpdi2q:
          return run_manufactured_solution_with<mpm::Cpdi2qShape, Real>(motion, method, n_cells, cfl, periods);
        case MmsShape::cubic_bspline_gimp:
          return run_manufactured_solution_with<mpm::CubicBSplineGimpShape, Real>(motion, method, n_cells, cfl,
                                                                                periods);
      }
    throw std::logic_error("run_manufactured_solution: unknown shape");
  }
} // namespace mpm_test
