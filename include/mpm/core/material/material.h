// The constitutive models known to the core, dispatched by a model tag so that
// device code needs no virtual calls. Adding a model: one header with its
// parameters and MPM_HOST_DEVICE update, one enum value, one case below, and one
// registration file in the deal.II layer (source/materials/).
#pragma once

#include <mpm/core/material/drucker_prager.h>
#include <mpm/core/material/linear_elastic.h>
#include <mpm/core/material/mohr_coulomb.h>

namespace mpm
{
  enum class MaterialModel : int
  {
    linear_elastic = 0,
    drucker_prager = 1, // non-associated, tension cut-off, inner fit to Mohr-Coulomb
    mohr_coulomb   = 2  // non-associated, principal-space return (plane, edge, apex)
  };

  template <typename Real>
  struct MaterialParameters
  {
    MaterialModel                 model;
    LinearElasticParameters<Real> elastic; // every model has an elastic part
    // Per-model data; only the one of `model` is read.
    DruckerPragerParameters<Real> drucker_prager;
    MohrCoulombParameters<Real>   mohr_coulomb;
    // false: plastic models behave elastically (elastic-loading phase before the prm time
    // at which plasticity is switched on); eps_p is then left unchanged.
    bool plasticity_enabled = true;
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
    // Every case: Jaumann rotation, elastic trial, then the model's return mapping.
    switch (m.model)
      {
        case MaterialModel::drucker_prager:
          drucker_prager_update(m.elastic, m.drucker_prager, m.plasticity_enabled, d_eps, d_spin, state.stress,
                                state.plastic_strain);
          break;
        case MaterialModel::mohr_coulomb:
          mohr_coulomb_update(m.elastic, m.mohr_coulomb, m.plasticity_enabled, d_eps, d_spin, state.stress,
                              state.plastic_strain);
          break;
        case MaterialModel::linear_elastic:
        default:
          linear_elastic_update(m.elastic, d_eps, d_spin, state.stress);
          break;
      }
  }
} // namespace mpm
