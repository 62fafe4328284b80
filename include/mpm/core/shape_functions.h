// Shape functions of the background grid, evaluated per point as 1D factors.
//
// Each family gives, along one direction, the first lattice node of the point's
// stencil and the weights and derivatives of the n_per_direction nodes from there
// (tensor_product; CPDI, which is not, lives in cpdi.h).
// Coordinates are in cell units (s = (x - origin) / h), so derivatives must be
// multiplied by 1/h by the caller. Tensor products build the dim-D stencil.
#pragma once

#include <mpm/core/config.h>
#include <mpm/core/shape/shape_traits.h>

#include <cmath>

namespace mpm
{
  // Standard MPM: the two nodes of the cell containing s.
  struct LinearShape
  {
    static constexpr const char *name        = "linear";
    static constexpr const char *description = "standard MPM";
    static constexpr ShapeOwner  owner       = ShapeOwner::always;
    static constexpr bool   point_domain                    = false;
    static constexpr double safe_distance_outside_home_cell = 1.0;
    static constexpr bool   apic                            = true;
    static constexpr double apic_inertia_over_h2            = 0;
    static constexpr bool   in_3d                           = true;
    static constexpr bool tensor_product  = true;
    static constexpr bool tracks_corners  = false;
    static constexpr int  n_per_direction = 2;
    static constexpr bool folds_boundary  = false;

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
    static constexpr const char *name        = "GIMP";
    static constexpr const char *description = "generalised interpolation";
    static constexpr ShapeOwner  owner       = ShapeOwner::always;
    static constexpr bool   point_domain                    = true;
    static constexpr double safe_distance_outside_home_cell = 0.5;
    static constexpr bool   apic                            = false;
    static constexpr double apic_inertia_over_h2            = 0;
    static constexpr bool   in_3d                           = true;
    static constexpr bool tensor_product  = true;
    static constexpr bool tracks_corners  = false;
    static constexpr int  n_per_direction = 3;
    static constexpr bool folds_boundary  = false; // weights beyond the lattice are zero for points inside

    template <typename Real>
    MPM_HOST_DEVICE static void
    weights_1d(const Real s, const Real lp, int &first, Real w[3], Real dw[3])
    {
      first = static_cast<int>(std::floor(s + Real(0.5))) - 1;
      for (int k = 0; k < 3; ++k)
        gimp_node_weight(s - Real(first + k), lp, w[k], dw[k]);
    }
  };

  // Quadratic B-spline (C1, support 3h) centred on each node: the nearest node and its two
  // neighbours. Within half a cell of a lattice face the stencil reaches a node outside the
  // lattice; fold_boundary (below) removes it.
  struct QuadraticBSplineShape
  {
    static constexpr const char *name        = "quadratic B-spline";
    static constexpr const char *description = "C1, three nodes per direction; within half a cell of the grid's faces it becomes linear, doc/theory.md";
    static constexpr ShapeOwner  owner       = ShapeOwner::always;
    static constexpr bool   point_domain                    = false;
    static constexpr double safe_distance_outside_home_cell = 0.5;
    static constexpr bool   apic                            = true;
    static constexpr double apic_inertia_over_h2            = 0.25;
    static constexpr bool   in_3d                           = true;
    static constexpr bool tensor_product  = true;
    static constexpr bool tracks_corners  = false;
    static constexpr int  n_per_direction = 3;
    static constexpr bool folds_boundary  = true;

    template <typename Real>
    MPM_HOST_DEVICE static void
    weights_1d(const Real s, const Real /*lp*/, int &first, Real w[3], Real dw[3])
    {
      first = static_cast<int>(std::floor(s + Real(0.5))) - 1;
      for (int k = 0; k < 3; ++k)
        {
          const Real r    = s - Real(first + k); // point minus node: d/dx_point = d/dr
          const Real a    = r < Real(0) ? -r : r;
          const Real sign = r < Real(0) ? Real(-1) : Real(1);
          if (a < Real(0.5))
            {
              w[k]  = Real(0.75) - r * r;
              dw[k] = Real(-2) * r;
            }
          else if (a < Real(1.5))
            {
              const Real b = Real(1.5) - a;
              w[k]         = Real(0.5) * b * b;
              dw[k]        = -sign * b;
            }
          else
            {
              w[k]  = Real(0);
              dw[k] = Real(0);
            }
        }
    }
  };

  // The cubic B-spline N(r) (support |r| < 2) and its slope dN/dr: the cubic B-spline's
  // weights, and the cubic B-spline GIMP's (cubic_bspline_gimp.h) where its domain is a point.
  template <typename Real>
  MPM_HOST_DEVICE inline void cubic_bspline_and_slope(const Real r, Real &w, Real &dw)
  {
    const Real a    = r < Real(0) ? -r : r;
    const Real sign = r < Real(0) ? Real(-1) : Real(1);
    if (a < Real(1))
      {
        w  = Real(2) / Real(3) - a * a + Real(0.5) * a * a * a;
        dw = sign * (Real(-2) * a + Real(1.5) * a * a);
      }
    else if (a < Real(2))
      {
        const Real b = Real(2) - a;
        w            = b * b * b / Real(6);
        dw           = -sign * Real(0.5) * b * b;
      }
    else
      {
        w  = Real(0);
        dw = Real(0);
      }
  }

  // Cubic B-spline (C2, support 4h) centred on each node: the two nodes of the point's cell
  // and one more on each side. Within one cell of a lattice face the stencil reaches a node
  // outside the lattice; fold_boundary (below) removes it.
  struct CubicBSplineShape
  {
    static constexpr const char *name        = "cubic B-spline";
    static constexpr const char *description = "C2, four nodes per direction, the same treatment at the faces; in MPI runs the points are re-sorted whenever one leaves its cell";
    static constexpr ShapeOwner  owner       = ShapeOwner::always;
    static constexpr bool   point_domain                    = false;
    static constexpr double safe_distance_outside_home_cell = 0.0;
    static constexpr bool   apic                            = true;
    static constexpr double apic_inertia_over_h2            = 1.0 / 3.0;
    static constexpr bool   in_3d                           = true;
    static constexpr bool tensor_product  = true;
    static constexpr bool tracks_corners  = false;
    static constexpr int  n_per_direction = 4;
    static constexpr bool folds_boundary  = true;

    template <typename Real>
    MPM_HOST_DEVICE static void
    weights_1d(const Real s, const Real /*lp*/, int &first, Real w[4], Real dw[4])
    {
      first = static_cast<int>(std::floor(s)) - 1;
      for (int k = 0; k < 4; ++k)
        cubic_bspline_and_slope(s - Real(first + k), w[k], dw[k]); // point minus node: d/dx_point = d/dr
    }
  };

  // Boundary treatment of the B-splines: the value at the ghost node one cell outside a face
  // is the linear extrapolation of the face node and its inner neighbour, u_ghost = 2 u_face
  // - u_inner, so the ghost's weight moves to them (x2 and x-1). Partition of unity and the
  // reproduction of linear fields hold up to the face, all weights stay >= 0, and no node
  // outside the lattice is used. Quadratic: within half a cell of the face the weights become
  // the linear hats 1 - r and r, meeting the B-splines C1 at r = 1/2. Cubic: the fold acts
  // in the face's cell only, where the ghost's weight (1 - r)^3 / 6 fades out C2 at r = 1.
  // n_cells: the lattice's cells along the direction; first, w, dw from Shape::weights_1d.
  template <typename Shape, typename Real>
  MPM_HOST_DEVICE inline void fold_boundary(const int n_cells, const int first, Real w[], Real dw[])
  {
    if constexpr (Shape::folds_boundary)
      {
        constexpr int n = Shape::n_per_direction;
        // The stencil starts at most one node below the lattice (node -1) and ends at most
        // one above (node n_cells + 1; the cubic's n_cells + 2 only for a point exactly on
        // the face, with weight 0), two nodes away from the stencil's far end.
        // The cubic averaged over a domain (five nodes, cubic_bspline_gimp.h) reaches one more
        // ghost on each side where its domain crosses the face: u = 3 u_face - 2 u_inner there.
        static_assert(n >= 3 && n <= 5, "the fold is written for three to five nodes per direction");
        for (int k = 0; k < n; ++k)
          {
            if constexpr (n == 5)
              {
                if (first + k == -2) // the second ghost below face 0
                  {
                    w[k + 2] += Real(3) * w[k];
                    w[k + 3] -= Real(2) * w[k];
                    dw[k + 2] += Real(3) * dw[k];
                    dw[k + 3] -= Real(2) * dw[k];
                    w[k] = dw[k] = Real(0);
                  }
                if (first + k == n_cells + 2) // the second ghost above face n_cells
                  {
                    w[k - 2] += Real(3) * w[k];
                    w[k - 3] -= Real(2) * w[k];
                    dw[k - 2] += Real(3) * dw[k];
                    dw[k - 3] -= Real(2) * dw[k];
                    w[k] = dw[k] = Real(0);
                  }
              }
            if (first + k == -1 && k + 2 < n) // the ghost below face 0
              {
                w[k + 1] += Real(2) * w[k];
                w[k + 2] -= w[k];
                dw[k + 1] += Real(2) * dw[k];
                dw[k + 2] -= dw[k];
                w[k] = dw[k] = Real(0);
              }
            if (first + k == n_cells + 1 && k >= 2) // the ghost above face n_cells
              {
                w[k - 1] += Real(2) * w[k];
                w[k - 2] -= w[k];
                dw[k - 1] += Real(2) * dw[k];
                dw[k - 2] -= dw[k];
                w[k] = dw[k] = Real(0);
              }
          }
      }
    else
      {
        (void)n_cells, (void)first, (void)w, (void)dw;
      }
  }

  // The weights of a point's stencil along one direction, boundary treatment included.
  template <typename Shape, typename Real>
  MPM_HOST_DEVICE inline void stencil_weights_1d(const Real s, const Real lp, const int n_cells, int &first, Real w[],
                                                 Real dw[])
  {
    Shape::weights_1d(s, lp, first, w, dw);
    fold_boundary<Shape>(n_cells, first, w, dw);
  }
} // namespace mpm
