// Shape functions of the background grid, evaluated per point as 1D factors.
//
// Each family gives, along one direction, the first lattice node of the point's
// stencil and the weights and derivatives of the n_per_direction nodes from there.
// Coordinates are in cell units (s = (x - origin) / h), so derivatives must be
// multiplied by 1/h by the caller. Tensor products build the dim-D stencil.
#pragma once

#include <mpm/core/config.h>

#include <cmath>

namespace mpm
{
  enum class ShapeFunction : int
  {
    linear = 0, // standard MPM: hat functions on the cell containing the point
    gimp   = 1  // generalised interpolation MP, particle domain of half-length lp
  };

  // Standard MPM: the two nodes of the cell containing s.
  struct LinearShape
  {
    static constexpr int n_per_direction = 2;

    template <typename Real>
    MPM_HOST_DEVICE static void
    weights_1d(const Real s, const Real /*lp*/, int &first, Real w[2], Real dw[2])
    {
      first        = static_cast<int>(std::floor(s));
      const Real r = s - Real(first); // in [0,1)
      w[0]         = Real(1) - r;
      w[1]         = r;
      dw[0]        = Real(-1);
      dw[1]        = Real(1);
    }
  };

  // uGIMP / cpGIMP weight of one node at signed distance r from the point centre,
  // for a particle of half-length lp (both in cell units, lp <= 1/2):
  // the hat function convolved with the particle's characteristic function.
  template <typename Real>
  MPM_HOST_DEVICE inline void gimp_node_weight(const Real r, const Real lp, Real &w, Real &dw)
  {
    const Real a    = r < Real(0) ? -r : r;
    const Real sign = r < Real(0) ? Real(-1) : Real(1);
    // dw is d/dx_point; r = x_point - x_node, so d/dx_point = d/dr.
    if (a < lp)
      {
        w  = Real(1) - (r * r + lp * lp) / (Real(2) * lp);
        dw = -r / lp;
      }
    else if (a < Real(1) - lp)
      {
        w  = Real(1) - a;
        dw = -sign;
      }
    else if (a < Real(1) + lp)
      {
        const Real b = Real(1) + lp - a;
        w            = b * b / (Real(4) * lp);
        dw           = -sign * b / (Real(2) * lp);
      }
    else
      {
        w  = Real(0);
        dw = Real(0);
      }
  }

  // GIMP: the nearest node and its two neighbours cover the support h + lp <= 3h/2.
  struct GimpShape
  {
    static constexpr int n_per_direction = 3;

    template <typename Real>
    MPM_HOST_DEVICE static void
    weights_1d(const Real s, const Real lp, int &first, Real w[3], Real dw[3])
    {
      first = static_cast<int>(std::floor(s + Real(0.5))) - 1;
      for (int k = 0; k < 3; ++k)
        gimp_node_weight(s - Real(first + k), lp, w[k], dw[k]);
    }
  };
} // namespace mpm
