// One quadrature point of the implicit small-strain FEM stage (issue 14): the built-in model's
// update over a strain increment, with its consistent tangent. The same physics as the MPM's
// update_stress (material.h) with no spin (small strain has no rotation to follow): elastic
// trial, the model's return mapping, explicit softening (strength at the start of the
// increment), the plasticity switch. Host only (the FEM stage runs on the CPU).
#pragma once

#include <mpm/core/material/consistent_tangent.h>
#include <mpm/core/material/material.h>

#include <stdexcept>

namespace mpm
{
  // stress, plastic_strain: the state at the start of the increment, updated in place;
  // C: d stress / d d_eps (consistent_tangent.h's convention). Returns the return mapping's
  // result (mode, multipliers, eps_p increment). A user model (user_model.h) gives no tangent:
  // it is refused with std::invalid_argument.
  inline ReturnResult<double> small_strain_update(const MaterialParameters<double> &m, const SymTensor<double> &d_eps,
                                                  SymTensor<double> &stress, double &plastic_strain, Tangent C)
  {
    if (m.model == MaterialModel::user_defined)
      throw std::invalid_argument("small_strain_update: a constitutive model defined outside the library gives no "
                                  "consistent tangent; the implicit FEM stage takes the built-in models only.");
    const SymTensor<double> d_sigma = elastic_stress_increment(m.elastic, d_eps);
    for (int c = 0; c < n_voigt; ++c)
      stress[c] += d_sigma[c];
    ReturnResult<double> r = elastic_return<double>();
    if (m.plasticity_enabled)
      with_built_in_model(m.model, [&](auto member) {
        using Member = decltype(member);
        r            = Member::tangent(m.elastic, parameters_of<Member>(m), plastic_strain, stress, C);
      });
    else
      elastic_tangent(m.elastic, C);
    plastic_strain += r.d_plastic_strain;
    return r;
  }
} // namespace mpm
