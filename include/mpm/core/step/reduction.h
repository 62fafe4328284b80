// The step's reductions over the points: the largest speed (next time step), the power of gravity.
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
#include <mpm/core/step/pressure_averaging.h>
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
  namespace stages
  {
    // The step's reductions (largest speed, power of gravity). With apply_averaging, the
    // same pass first gathers the cell pressure back into each point (reduce_points calls
    // the per-point function exactly once per point): one pass over the points less.
    template <int dim, typename Real, typename Backend>
    StepReduction<Real> reduce_step(Backend &backend, const GridView<dim, Real> &g, const PointsView<dim, Real> &p,
                                    const StepSettings<dim, Real> &s, const bool apply_averaging = false,
                                    const MaterialParameters<Real> *disconnecting = nullptr)
    {
      StepReduction<Real> init{Real(0), Real(0), Real(0)};
      return backend.reduce_points(
        p.n_points, init,
        [=] MPM_HOST_DEVICE(const int i) {
          if (apply_averaging && p.material[i] >= 0)
            apply_cell_pressure(g, p, i, disconnecting);
          StepReduction<Real> r{Real(0), Real(0), Real(0)};
          Real v2 = Real(0);
          for (int d = 0; d < dim; ++d)
            v2 += p.velocity[d][i] * p.velocity[d][i];
          if (p.material[i] < 0)
            {
              r.max_removed_speed = std::sqrt(v2);
              return r;
            }
          for (int d = 0; d < dim; ++d)
            r.gravity_power += p.mass[i] * s.gravity[d] * p.velocity[d][i];
          r.max_speed = std::sqrt(v2);
          return r;
        },
        // A speed that is not a number wins the maximum (a != a): a blow-up cannot hide behind
        // the order in which the threads combine.
        [] MPM_HOST_DEVICE(const StepReduction<Real> &a, const StepReduction<Real> &b) {
          return StepReduction<Real>{a.max_speed > b.max_speed || a.max_speed != a.max_speed ? a.max_speed :
                                                                                                b.max_speed,
                                     a.gravity_power + b.gravity_power,
                                     a.max_removed_speed > b.max_removed_speed ||
                                         a.max_removed_speed != a.max_removed_speed ?
                                       a.max_removed_speed :
                                       b.max_removed_speed};
        });
    }
  } // namespace stages
} // namespace mpm
