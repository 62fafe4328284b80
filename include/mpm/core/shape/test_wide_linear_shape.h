// A test's member of the shape-function family: the linear hats of LinearShape, evaluated on
// the three-node stencil of GIMP (first node floor(s + 1/2) - 1) with the third node's weight
// zero. The same function as linear, so a run with it moves as a linear run does; what differs
// is everything the family derives from the traits (the stencil's width, the migration margin,
// the sort key, the prm name, the device variant). Owned by `test`: in no user's prm.
#pragma once

#include <mpm/core/config.h>
#include <mpm/core/shape_functions.h>

#include <cmath>

namespace mpm
{
  struct TestWideLinearShape
  {
    static constexpr const char *name        = "test wide linear";
    static constexpr const char *description = "a test's member: linear hats on a three-node stencil";
    static constexpr ShapeOwner  owner       = ShapeOwner::test;
    static constexpr bool        tensor_product  = true;
    static constexpr bool        tracks_corners  = false;
    static constexpr int         n_per_direction = 3;
    static constexpr bool        folds_boundary  = false;
    static constexpr bool   point_domain                    = false;
    static constexpr double safe_distance_outside_home_cell = 0.5; // as GIMP's stencil
    static constexpr bool   apic                            = true;
    static constexpr double apic_inertia_over_h2            = 0;
    static constexpr bool   in_3d                           = true;

    template <typename Real>
    MPM_HOST_DEVICE static void weights_1d(const Real s, const Real lp, int &first, Real w[3], Real dw[3])
    {
      int  cell;
      Real w_cell[2], dw_cell[2];
      LinearShape::weights_1d(s, lp, cell, w_cell, dw_cell);
      first              = static_cast<int>(std::floor(s + Real(0.5))) - 1; // cell - 1 or cell
      const int offset   = cell - first;
      for (int k = 0; k < 3; ++k)
        {
          const int j = k - offset;
          w[k]        = j == 0 || j == 1 ? w_cell[j] : Real(0);
          dw[k]       = j == 0 || j == 1 ? dw_cell[j] : Real(0);
        }
    }
  };
} // namespace mpm
