// The constitutive models known to the core, dispatched by a model tag so that
// device code needs no virtual calls. Adding a built-in model: one header with its
// parameters and MPM_HOST_DEVICE update, one enum value, one case below, and one
// registration file in the deal.II layer (source/dealii/materials/). A model written outside
// the library (user_model.h) is the tag user_defined and a pointer; CPU backend only.
#pragma once

#include <mpm/core/material/drucker_prager.h>
#include <mpm/core/material/hencky.h>
#include <mpm/core/material/linear_elastic.h>
#include <mpm/core/material/mohr_coulomb.h>
#include <mpm/core/material/user_model.h>

#include <cmath>
#include <type_traits>

namespace mpm
{
  enum class MaterialModel : int
  {
    linear_elastic = 0,
    drucker_prager = 1, // non-associated, tension cut-off, inner fit to Mohr-Coulomb
    mohr_coulomb   = 2, // non-associated, principal-space return (plane, edge, apex)
    user_defined   = 3  // UserConstitutiveModel, a virtual call per point (CPU only)
  };

  // A material parameter that varies from point to point (a random field sampled at the
  // points, PointsView::material_field): the point's value replaces the material's.
  enum class FieldParameter : int
  {
    none           = 0,
    cohesion       = 1, // c_peak; c_res keeps its ratio to c_peak
    friction_angle = 2, // phi_peak (rad); phi_res keeps its difference to phi_peak
    youngs_modulus = 3
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
    FieldParameter field_parameter = FieldParameter::none;
    // The elastic part's form (hencky.h); built-in models only. The device compiles Hencky's law
    // only into the step's DevicePhysics::all variant (step.h), which DeviceEngine runs where a
    // material asks for it.
    ElasticLaw elastic_law = ElasticLaw::jaumann_rate;
    // A point dilated beyond this multiple of its initial volume has lost contact and carries
    // no stress (disconnected, below); 0: never. The MPM step's update only.
    Real disconnection_volume_ratio = Real(0);
    // model == user_defined: the model (host memory; owned by the material library).
    const UserConstitutiveModel *user_model = nullptr;
  };

  // Per-point state a constitutive update reads and writes.
  template <typename Real>
  struct MaterialPointState
  {
    SymTensor<Real> stress;
    Real            plastic_strain;
    Real           *state_variables = nullptr; // a user model's own (host only), null if none
  };

  template <typename Real>
  MPM_HOST_DEVICE inline void set_field_strength(SofteningStrength<Real> &s, const FieldParameter which,
                                                 const Real value)
  {
    if (which == FieldParameter::cohesion)
      {
        s.residual_cohesion = s.cohesion > Real(0) ? s.residual_cohesion * (value / s.cohesion) : Real(0);
        s.cohesion          = value;
      }
    else if (which == FieldParameter::friction_angle)
      {
        s.residual_friction_angle += value - s.friction_angle;
        s.friction_angle = value;
        if (s.dilatancy_angle > value)
          s.dilatancy_angle = value;
      }
  }

  // The material as seen by one point whose field value is `value`.
  template <typename Real>
  MPM_HOST_DEVICE inline MaterialParameters<Real> with_field_value(MaterialParameters<Real> m, const Real value)
  {
    if (m.field_parameter == FieldParameter::youngs_modulus)
      m.elastic.youngs_modulus = value;
    set_field_strength(m.drucker_prager.strength, m.field_parameter, value);
    set_field_strength(m.mohr_coulomb.strength, m.field_parameter, value);
    return m;
  }

  // The P-wave modulus K + 4G/3 of a point whose field value is `value`: the stiffness of its
  // fastest elastic wave, which bounds the explicit step (CFL). A random field of Young's
  // modulus makes it the point's own, not the material's mean.
  template <typename Real>
  MPM_HOST_DEVICE inline Real point_p_wave_modulus(const MaterialParameters<Real> &m, const Real value)
  {
    return m.field_parameter == FieldParameter::youngs_modulus ? with_field_value(m, value).elastic.p_wave_modulus() :
                                                                   m.elastic.p_wave_modulus();
  }

  // The update of a point that knows its whole motion over the step (the MPM step): the
  // material's elastic law picks the Jaumann rate form or Hencky's. all_laws = false leaves
  // Hencky's law and Mohr-Coulomb out of the compiled code (the device's standard kernels,
  // step.h's DevicePhysics): the caller must have made sure no material asks for either
  // (materials_need_all_physics, step.h); one that does gets a NaN stress, which the step reports.
  template <bool all_laws = true, typename Real>
  MPM_HOST_DEVICE inline void update_stress(const MaterialParameters<Real> &m, const StepKinematics<Real> &k,
                                            MaterialPointState<Real> &state);

  template <bool all_laws = true, typename Real>
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
          // Its eigen decomposition (with U's domains) made the standard FP64 kinematics spill:
          // 614 / 1,024 bytes of spill stores / loads at 96 registers against 142 / 272 without
          // them (nvcc, 2026-12-05, doc/performance.md); they leave it out.
          if constexpr (all_laws)
            mohr_coulomb_update(m.elastic, m.mohr_coulomb, m.plasticity_enabled, d_eps, d_spin, state.stress,
                                state.plastic_strain);
          else
            for (int c = 0; c < n_voigt; ++c)
              state.stress[c] = Real(NAN);
          break;
        case MaterialModel::user_defined:
#ifndef __CUDA_ARCH__
          // The interface is double; only the CPU backend runs user models, and it steps in double.
          if constexpr (std::is_same_v<Real, double>)
            m.user_model->update_stress(d_eps, d_spin, m.plasticity_enabled, state.stress, state.plastic_strain,
                                        state.state_variables);
#endif
          break;
        case MaterialModel::linear_elastic:
        default:
          linear_elastic_update(m.elastic, d_eps, d_spin, state.stress);
          break;
      }
  }

  // A granular point dilated so far that its grains have lost contact (the disconnected phase
  // of Dunatunga and Kamrin 2015, J. Fluid Mech. 779): it carries no stress, and compacted
  // back below the ratio its stress starts again from zero. Without it a cohesionless point
  // dilated to hundreds of times its volume at a thin front (tension leaves it stress-free,
  // nothing stops the growth) takes the stress of its first recompression on that whole
  // volume, a force the size of hundreds of points' (doc/methods.md, "Disconnected points").
  template <typename Real>
  MPM_HOST_DEVICE inline bool disconnected(const MaterialParameters<Real> &m, const Real J)
  {
    return m.disconnection_volume_ratio > Real(0) && J > m.disconnection_volume_ratio;
  }

  template <bool all_laws, typename Real>
  MPM_HOST_DEVICE inline void update_stress(const MaterialParameters<Real> &m, const StepKinematics<Real> &k,
                                            MaterialPointState<Real> &state)
  {
    if (disconnected(m, k.J_new)) // no stress, no plastic flow, no state change
      {
        state.stress = SymTensor<Real>::zero();
        return;
      }
    if constexpr (all_laws)
      {
        if (m.elastic_law == ElasticLaw::hencky && m.model != MaterialModel::user_defined)
          {
            switch (m.model)
              {
                case MaterialModel::drucker_prager:
                  hencky_update(m.elastic, m.plasticity_enabled, k, state.stress, state.plastic_strain,
                                [&](SymTensor<Real> &tau, const Real eps_p) {
                                  return drucker_prager_return(m.elastic,
                                                               drucker_prager_coefficients_at(m.drucker_prager, eps_p),
                                                               tau);
                                });
                  break;
                case MaterialModel::mohr_coulomb:
                  hencky_update(m.elastic, m.plasticity_enabled, k, state.stress, state.plastic_strain,
                                [&](SymTensor<Real> &tau, const Real eps_p) {
                                  return mohr_coulomb_return(m.elastic, current_strength(m.mohr_coulomb.strength, eps_p),
                                                             tau);
                                });
                  break;
                default:
                  hencky_update(m.elastic, false, k, state.stress, state.plastic_strain,
                                [](SymTensor<Real> &, const Real) { return elastic_return<Real>(); });
                  break;
              }
            return;
          }
      }
    update_stress<all_laws>(m, k.d_eps, k.d_spin, state);
  }
} // namespace mpm
