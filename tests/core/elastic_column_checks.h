// The V1 acceptance checks, on any Target: cpGIMP (F_ii domains) converges (observed order
// >= 1.5 between the two finest levels, error < 1e-3 at the finest); standard MPM on the
// same scene, where points cross cells, shows a larger error than GIMP (cell-crossing
// noise, at least 5x). Pure FLIP, MUSL, linear gravity ramp over 40 transit times, run to
// 2 t_ramp. Local damping D = 0.05 removes the free vibration that the ramp's start
// excites (amplitude ~ v_static / omega, an error that undamped FLIP keeps for ever); it
// does not change the static solution (doc/validation.md).
#pragma once

#include "check.h"
#include "elastic_column.h"

#include <mpm/core/cubic_bspline_gimp.h>

#include <cstdio>
#include <vector>

namespace mpm_test
{
  template <template <int, typename> class Target>
  void check_column_convergence(const std::vector<int> &levels, const bool assert_targets)
  {
    using namespace mpm;
    std::printf("%8s %12s %12s %10s %8s\n", "cells", "error GIMP", "error sMPM", "steps", "order");
    std::vector<double> errors;
    double              last_smpm = 0;
    for (const int n : levels)
      {
        HostPoints<2, double> points;
        const ColumnResult gimp = elastic_column<GimpShape, Target>({n, 0.5, DomainUpdate::stretch}, points);
        const ColumnResult smpm = elastic_column<LinearShape, Target>({n, 0.5, DomainUpdate::none}, points);
        const double       order = errors.empty() ? 0 : std::log2(errors.back() / gimp.error);
        errors.push_back(gimp.error);
        last_smpm = smpm.error;
        std::printf("%8d %12.4e %12.4e %10ld %8.2f\n", n, gimp.error, smpm.error, gimp.n_steps, order);
      }
    if (!assert_targets)
      return;
    const double order = std::log2(errors[errors.size() - 2] / errors.back());
    for (size_t i = 1; i < errors.size(); ++i)
      check(errors[i] < errors[i - 1], "GIMP error decreases with refinement", errors[i], errors[i - 1]);
    check(order >= 1.5, "observed order between the finest levels >= 1.5", order, 1.5);
    check_below(errors.back(), 1e-3, "finest-level error below 1e-3");
    check(last_smpm > 5 * errors.back(), "sMPM error exceeds 5x GIMP's", last_smpm, 5 * errors.back());
  }

  // A B-spline (quadratic or cubic) on the column. With V1's compression of 78% the quadratic's
  // error stalls near 6e-3 (the points' quadrature of the B-splines degrades as they crowd:
  // doc/methods.md), so it is asserted at small strain (E = 1 MPa, 0.78%), where the B-splines
  // converge at second order. assert_targets: order >= 1.8 at each refinement, error < 1e-4
  // at the finest, below cpGIMP's at every level.
  template <typename Shape, template <int, typename> class Target>
  void check_bspline_column(const char *name, const std::vector<int> &levels, const bool assert_targets)
  {
    using namespace mpm;
    std::printf("%s\n%8s %14s %14s %8s %14s\n", name, "cells", "B-spline 1MPa", "GIMP 1MPa", "order", "B-spline V1");
    std::vector<double> errors;
    const std::string   what = name;
    for (const int n : levels)
      {
        HostPoints<2, double> points;
        ColumnSetup           small{n, 0.5, DomainUpdate::none};
        small.youngs_modulus    = 1e6;
        const ColumnResult b    = elastic_column<Shape, Target>(small, points);
        small.domain_update     = DomainUpdate::stretch;
        const ColumnResult gimp = elastic_column<GimpShape, Target>(small, points);
        const ColumnResult v1   = elastic_column<Shape, Target>({n, 0.5, DomainUpdate::none}, points);
        const double       order = errors.empty() ? 0 : std::log2(errors.back() / b.error);
        std::printf("%8d %14.4e %14.4e %8.2f %14.4e\n", n, b.error, gimp.error, order, v1.error);
        if (assert_targets && !errors.empty())
          check(order >= 1.8, (what + ", small strain: observed order >= 1.8").c_str(), order, 1.8);
        if (assert_targets)
          check(b.error < gimp.error, (what + ", small strain: more accurate than cpGIMP").c_str(), b.error,
                gimp.error);
        errors.push_back(b.error);
      }
    if (assert_targets)
      check_below(errors.back(), 1e-4, (what + ", small strain: finest-level error below 1e-4").c_str());
  }
  // V1 itself (E = 10 kPa, 78% compression) with the cubic B-spline GIMP, its domains
  // following F_ii: the acceptance target of issue 15, an error <= 1e-5 at 256 cells and
  // an order >= 1.8 from 8 to 256 cells (the least-squares slope of log error against log
  // h over the levels). Local damping 0.5 instead of 0.05 brings the column to rest within
  // 2 t_ramp (the static answer does not depend on it), and FLIP 0.99 (the program's
  // blend) keeps the points below the free surface from drifting (pure FLIP: 2.2e-5 at
  // 256 cells; doc/methods.md, "V1 column").
  template <template <int, typename> class Target>
  void check_bspline_gimp_column(const std::vector<int> &levels, const bool assert_targets)
  {
    using namespace mpm;
    std::printf("cubic B-spline GIMP, V1 (E = 10 kPa), F_ii domains, damping 0.5, FLIP 0.99\n%8s %12s %8s %10s\n",
                "cells", "error", "order", "steps");
    std::vector<double> errors;
    double              sx = 0, sy = 0, sxx = 0, sxy = 0;
    for (const int n : levels)
      {
        HostPoints<2, double> points;
        ColumnSetup           v1{n, 0.5, DomainUpdate::stretch};
        v1.damping             = 0.5;
        v1.flip_fraction       = 0.99;
        const ColumnResult r   = elastic_column<CubicBSplineGimpShape, Target>(v1, points);
        const double       order = errors.empty() ? 0 : std::log2(errors.back() / r.error);
        std::printf("%8d %12.4e %8.2f %10ld\n", n, r.error, order, r.n_steps);
        errors.push_back(r.error);
        const double x = std::log2(double(n)), y = std::log2(r.error);
        sx += x, sy += y, sxx += x * x, sxy += x * y;
      }
    const double m     = double(levels.size());
    const double slope = -(m * sxy - sx * sy) / (m * sxx - sx * sx);
    std::printf("order from %d to %d cells (least squares): %.2f\n", levels.front(), levels.back(), slope);
    if (!assert_targets)
      return;
    check(slope >= 1.8, "cubic B-spline GIMP on V1: order >= 1.8 over the levels", slope, 1.8);
    check_below(errors.back(), 1e-5, "cubic B-spline GIMP on V1: error <= 1e-5 at the finest level");
  }
} // namespace mpm_test
