// Local (Cundall) damping of a node's out-of-balance force, in two forms (doc/theory.md,
// "Local damping"). Each component of the force is reduced by D times a magnitude, against
// the direction of the node's velocity in that component:
//   per component:  f_i <- f_i - D |f_i| sign(v_i)   (Cundall's form; the default)
//   force norm:     f_i <- f_i - D |f|   sign(v_i)   (ep2-3De's form), |f| the norm of the
//                   whole nodal force, the components a boundary holds fixed included.
// The per-component form removes power only where force and motion act in the same
// component, so a body at rest in static equilibrium (f = 0) is not held by it. The
// force-norm form lets a large force in one component (the vertical while gravity loads,
// or the normal reaction on a free-slip wall) oppose motion in the others, like friction:
// it can hold a body away from equilibrium (doc/validation-v5.md).
// Components with speed |v_i| <= threshold are not damped.
#pragma once

#include <mpm/core/config.h>

#include <cmath>

namespace mpm
{
  enum class LocalDampingForm : int
  {
    per_component = 0,
    force_norm    = 1
  };

  // The norm |f| of a node's whole force, for the force-norm form (0 for the other: unused).
  template <int dim, typename Real>
  MPM_HOST_DEVICE inline Real local_damping_norm(const Real f[dim], const LocalDampingForm form)
  {
    Real norm = Real(0);
    if (form == LocalDampingForm::force_norm)
      {
        for (int d = 0; d < dim; ++d)
          norm += f[d] * f[d];
        norm = std::sqrt(norm);
      }
    return norm;
  }

  // One damped component: f is the component, v the node's velocity in it, norm from
  // local_damping_norm. The grid update calls it component by component.
  template <typename Real>
  MPM_HOST_DEVICE inline Real damped_force_component(const Real f, const Real v, const Real norm, const Real damping,
                                                     const LocalDampingForm form, const Real threshold)
  {
    if (!(std::fabs(v) > threshold))
      return f;
    const Real magnitude = form == LocalDampingForm::force_norm ? norm : std::fabs(f);
    return f - damping * magnitude * (v > Real(0) ? Real(1) : Real(-1));
  }

  // The same for a whole node, in place: f its force, v its velocity.
  template <int dim, typename Real>
  MPM_HOST_DEVICE inline void apply_local_damping(Real f[dim], const Real v[dim], const Real damping,
                                                  const LocalDampingForm form, const Real threshold = Real(0))
  {
    const Real norm = local_damping_norm<dim>(f, form);
    for (int d = 0; d < dim; ++d)
      f[d] = damped_force_component(f[d], v[d], norm, damping, form, threshold);
  }
} // namespace mpm
