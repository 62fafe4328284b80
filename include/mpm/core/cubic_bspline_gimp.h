// The cubic B-spline averaged over a point's domain [s - lp, s + lp] (cell units), as
// GIMP averages the linear hat: w_i = (M(r + lp) - M(r - lp)) / (2 lp) with M the
// antiderivative of the B-spline and r = s - x_i. Where the domains follow the
// deformation and tile the body (cpGIMP's domain update), a stress that is constant per
// domain is integrated exactly, so the quadrature error that stalls the plain B-spline
// on V1's compressed column goes away (doc/methods.md, "V1 column").
#pragma once

#include <mpm/core/shape_functions.h>

namespace mpm
{
  // The cubic B-spline (shape_functions.h) and its antiderivative from -2 (M(-2) = 0,
  // M(0) = 1/2, M(2) = 1).
  template <typename Real>
  MPM_HOST_DEVICE inline Real cubic_bspline(const Real r)
  {
    Real w, slope;
    cubic_bspline_and_slope(r, w, slope);
    return w;
  }

  template <typename Real>
  MPM_HOST_DEVICE inline Real cubic_bspline_integral(const Real r)
  {
    // Odd about r = 0 up to the constant 1/2: M(r) = 1/2 + sign(r) P(|r|).
    const Real a = r < Real(0) ? -r : r;
    Real       p; // integral of the B-spline from 0 to a
    if (a < Real(1))
      p = Real(2) / Real(3) * a - a * a * a / Real(3) + a * a * a * a / Real(8);
    else if (a < Real(2))
      {
        const Real b = Real(2) - a;
        p            = Real(0.5) - b * b * b * b / Real(24);
      }
    else
      p = Real(0.5);
    return r < Real(0) ? Real(0.5) - p : Real(0.5) + p;
  }

  // Support 2 + lp on each side (lp < 1/2): five nodes from floor(s - lp) - 1. As the other
  // shapes' weights_1d: s is the point's coordinate and lp its domain's half-length, both in
  // cell units; it gives the first node's lattice index and the five nodes' weights w and
  // derivatives dw = dw/ds (multiply by 1/h for d/dx). Near a lattice face the ghost nodes
  // fold as for the plain cubic (fold_boundary, applied by stencil_weights_1d).
  struct CubicBSplineGimpShape
  {
    static constexpr const char *name        = "cubic B-spline GIMP";
    static constexpr const char *description = "the cubic B-spline averaged over each point's axis-aligned domain, five nodes per direction; with GIMP domain update = F_ii, det F or U the domains follow the deformation";
    static constexpr ShapeOwner  owner       = ShapeOwner::always;
    static constexpr bool   point_domain                    = true;
    // It weighs the nodes within 2 + lp of the point: from home cell [c, c + 1] up to node c + 3
    // once s > c + 1/2, half a cell beyond the ring even from inside the cell (one MPI rank).
    static constexpr double safe_distance_outside_home_cell = -0.5;
    static constexpr bool   apic                            = false;
    static constexpr double apic_inertia_over_h2            = 0;
    static constexpr bool   in_3d                           = true;
    static constexpr bool tensor_product  = true;
    static constexpr bool tracks_corners  = false;
    static constexpr int  n_per_direction = 5;
    static constexpr bool folds_boundary  = true;

    template <typename Real>
    MPM_HOST_DEVICE static void weights_1d(const Real s, const Real lp, int &first, Real w[5], Real dw[5])
    {
      first = static_cast<int>(std::floor(s - lp)) - 1;
      // Below 1e-4 cells the average differs from the point value by about lp^2 / 6, far
      // below round-off of the difference quotient's cancellation.
      const bool point_value = !(lp > Real(1e-4));
      for (int k = 0; k < 5; ++k)
        {
          const Real r = s - Real(first + k); // point minus node: d/dx_point = d/dr
          if (point_value)
            cubic_bspline_and_slope(r, w[k], dw[k]);
          else
            {
              const Real inverse_length = Real(0.5) / lp;
              w[k]  = (cubic_bspline_integral(r + lp) - cubic_bspline_integral(r - lp)) * inverse_length;
              dw[k] = (cubic_bspline(r + lp) - cubic_bspline(r - lp)) * inverse_length;
            }
        }
    }
  };
} // namespace mpm
