// Shear strength reduction (the factor of safety of an FEM analysis, issue 14): the material
// with c, tan(phi) and tan(psi) divided by a factor F. Softening follows: the residual
// strength is reduced alike and the softening modulus H by F, so the whole c(eps_p) curve is
// scaled and the strain at which it reaches c_res is unchanged; the Drucker-Prager tension
// cut-off, a strength too, is divided by F. Linear elastic and user models are unchanged.
#pragma once

#include <mpm/core/material/material.h>

#include <cmath>

namespace mpm
{
  template <typename Real>
  MPM_HOST_DEVICE inline Real reduced_angle(const Real angle, const Real factor)
  {
    return std::atan(std::tan(angle) / factor);
  }

  template <typename Real>
  MPM_HOST_DEVICE inline SofteningStrength<Real> reduced_strength(SofteningStrength<Real> s, const Real factor)
  {
    s.cohesion                = s.cohesion / factor;
    s.residual_cohesion       = s.residual_cohesion / factor;
    s.softening_modulus       = s.softening_modulus / factor;
    s.friction_angle          = reduced_angle(s.friction_angle, factor);
    s.residual_friction_angle = reduced_angle(s.residual_friction_angle, factor);
    s.dilatancy_angle         = reduced_angle(s.dilatancy_angle, factor);
    return s;
  }

  // The material at strength reduction factor F (> 0; F = 1 gives it back unchanged).
  template <typename Real>
  MPM_HOST_DEVICE inline MaterialParameters<Real> with_reduced_strength(MaterialParameters<Real> m, const Real factor)
  {
    if (factor == Real(1))
      return m;
    if (m.model == MaterialModel::drucker_prager)
      {
        m.drucker_prager.strength         = reduced_strength(m.drucker_prager.strength, factor);
        m.drucker_prager.tensile_strength = m.drucker_prager.tensile_strength / factor;
      }
    else if (m.model == MaterialModel::mohr_coulomb)
      m.mohr_coulomb.strength = reduced_strength(m.mohr_coulomb.strength, factor);
    return m;
  }
} // namespace mpm
