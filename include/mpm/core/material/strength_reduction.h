// Shear strength reduction (the factor of safety of an FEM analysis, issue 14): the material
// with c, tan(phi) and tan(psi) divided by a factor F. Softening follows: the residual
// strength is reduced alike and the softening modulus H by F, so the whole c(eps_p) curve is
// scaled and the strain at which it reaches c_res is unchanged; the Drucker-Prager tension
// cut-off, a strength too, is divided by F. Each model says what it reduces (its reduced(),
// material_family.h); linear elastic and user models are unchanged.
#pragma once

#include <mpm/core/material/material.h>

#include <cmath>

namespace mpm
{
  // The material at strength reduction factor F (> 0; F = 1 gives it back unchanged).
  template <typename Real>
  MPM_HOST_DEVICE inline MaterialParameters<Real> with_reduced_strength(MaterialParameters<Real> m, const Real factor)
  {
    if (factor == Real(1))
      return m;
    with_built_in_model(m.model, [&](auto member) {
      using Member               = decltype(member);
      parameters_of<Member>(m) = Member::reduced(parameters_of<Member>(m), factor);
    });
    return m;
  }
} // namespace mpm
