// A point's domain as the stencil reads it (GIMP half-lengths, CPDI's R = F R_0, CPDI2q's corners).
// Part of the explicit step (step.h); header-only, host and device.
#pragma once

#include <cmath>
#include <mpm/core/cubic_bspline_gimp.h>
#include <mpm/core/domain_update.h>
#include <mpm/core/interpolation.h>
#include <mpm/core/local_damping.h>
#include <mpm/core/material/material.h>
#include <mpm/core/prefetch.h>
#include <mpm/core/shape_functions.h>
#include <mpm/core/small_tensor.h>
#include <mpm/core/stencil_contribution.h>
#include <mpm/core/step/settings.h>
#include <mpm/core/views.h>
#include <mpm/core/wall_friction.h>
#include <stdexcept>
#include <type_traits>
#include <utility>

#include <cmath>
#include <stdexcept>
#include <type_traits>
#include <utility>

namespace mpm
{
  // A point's domain as the stencil reads it (domain_values<dim, Shape>() values): the
  // current half-lengths for the tensor-product shapes; CPDI's R = F R_0 (cpdi.h), R_0 the
  // initial half-lengths on the diagonal, from the point's F of the step's start; CPDI2q's
  // corner offsets q_c = R_0 s_c + delta_c, delta_c from the state variables.
  template <int dim, typename Shape, typename Real>
  MPM_HOST_DEVICE inline void load_domain(const PointsView<dim, Real> &p, const StepSettings<dim, Real> &s,
                                          const int i, Real *domain)
  {
    if constexpr (Shape::tensor_product)
      for (int d = 0; d < dim; ++d)
        domain[d] = p.domain_half_length[d][i];
    else if constexpr (Shape::tracks_corners)
      for (int c = 0; c < (1 << dim); ++c)
        for (int d = 0; d < dim; ++d)
          domain[c * dim + d] = ((c >> d) & 1 ? p.initial_domain_half_length[d][i] :
                                                -p.initial_domain_half_length[d][i]) +
                                p.state_variables[s.corner_state_variable + c * dim + d][i];
    else
      for (int a = 0; a < dim; ++a)
        for (int b = 0; b < dim; ++b)
          domain[a * dim + b] = p.deformation_gradient[a * dim + b][i] * p.initial_domain_half_length[b][i];
  }
} // namespace mpm
