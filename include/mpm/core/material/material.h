// The constitutive models known to the core, dispatched by a model tag so that
// device code needs no virtual calls. Adding a model: one header with its
// parameters and MPM_HOST_DEVICE update, one enum value, one case below, and one
// registration file in the deal.II layer (source/materials/).
#pragma once

#include <mpm/core/material/linear_elastic.h>

namespace mpm
{
  enum class MaterialModel : int
  {
    linear_elastic = 0
  };

  template <typename Real>
  struct MaterialParameters
  {
    MaterialModel                 model;
    LinearElasticParameters<Real> elastic; // every model has an elastic part
  };

  // Per-point state a constitutive update reads and writes.
  template <typename Real>
  struct MaterialPointState
  {
    SymTensor<Real> stress;
    Real            plastic_strain;
  };

  template <typename Real>
  MPM_HOST_DEVICE inline void update_stress(const MaterialParameters<Real> &m,
                                            const SymTensor<Real>          &d_eps,
                                            const Mat3<Real>               &d_spin,
                                            MaterialPointState<Real>       &state)
  {
    switch (m.model)
      {
        case MaterialModel::linear_elastic:
        default:
          linear_elastic_update(m.elastic, d_eps, d_spin, state.stress);
          break;
      }
  }
} // namespace mpm
