// The constitutive models known to the core, dispatched by a model tag so that device code
// needs no virtual calls. The built-in models are the material family (material_family.h: one
// header per model and one line in its list); a model written outside the library
// (user_model.h) is the tag user_defined and a pointer, CPU backend only.
#pragma once

#include <mpm/core/material/hencky.h>
#include <mpm/core/material/material_family.h>
#include <mpm/core/material/user_model.h>

#include <cmath>
#include <type_traits>

namespace mpm
{
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
    // Per-model data, one member per built-in model named by its identifier (material_family.h);
    // only the one of `model` is read.
#define MPM_MATERIAL_PARAMETERS(identifier, Member) typename Member::template Parameters<Real> identifier;
    MPM_BUILT_IN_MATERIALS(MPM_MATERIAL_PARAMETERS)
#undef MPM_MATERIAL_PARAMETERS
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

  // The parameters of built-in member Member in m (m.identifier).
  template <typename Member>
  struct MaterialSlot;
#define MPM_MATERIAL_SLOT(identifier, Member)                      \
  template <>                                                      \
  struct MaterialSlot<Member>                                      \
  {                                                                \
    template <typename Material>                                   \
    MPM_HOST_DEVICE static auto &of(Material &m)                   \
    {                                                              \
      return m.identifier;                                         \
    }                                                              \
  };
  MPM_BUILT_IN_MATERIALS(MPM_MATERIAL_SLOT)
#undef MPM_MATERIAL_SLOT

  template <typename Member, typename Material>
  MPM_HOST_DEVICE inline auto &parameters_of(Material &m)
  {
    return MaterialSlot<Member>::of(m);
  }

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
#define MPM_MATERIAL_FIELD(identifier, Member)                           \
    if (SofteningStrength<Real> *s = Member::strength(m.identifier))     \
      set_field_strength(*s, m.field_parameter, value);
    MPM_BUILT_IN_MATERIALS(MPM_MATERIAL_FIELD)
#undef MPM_MATERIAL_FIELD
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

  // Whether the device's standard kernels compile the model of `m` (model_traits.h); the others
  // run in DevicePhysics::all only (step.h). User models never run on the device.
  template <typename Real>
  MPM_HOST_DEVICE inline bool in_standard_kernels(const MaterialParameters<Real> &m)
  {
    return built_in_model_is(m.model, [](auto member) { return decltype(member)::in_standard_kernels; }, true);
  }

  // The update of a point with a strain and spin increment (Jaumann rate form): rotation,
  // elastic trial, the model's return mapping (explicit softening). all_laws = false leaves the
  // models outside the standard kernels out of the compiled code (the device's standard
  // kernels, step.h's DevicePhysics): the caller must have made sure no material asks for one
  // (materials_need_all_physics, step.h); one that does gets a NaN stress, which the step reports.
  template <bool all_laws = true, typename Real>
  MPM_HOST_DEVICE inline void update_stress(const MaterialParameters<Real> &m,
                                            const SymTensor<Real>          &d_eps,
                                            const Mat3<Real>               &d_spin,
                                            MaterialPointState<Real>       &state)
  {
    if (m.model == MaterialModel::user_defined)
      {
#ifndef __CUDA_ARCH__
        // The interface is double; only the CPU backend runs user models, and it steps in double.
        if constexpr (std::is_same_v<Real, double>)
          m.user_model->update_stress(d_eps, d_spin, m.plasticity_enabled, state.stress, state.plastic_strain,
                                      state.state_variables);
#endif
        return;
      }
    with_built_in_model(m.model, [&](auto member) {
      using Member = decltype(member);
      if constexpr (all_laws || Member::in_standard_kernels)
        {
          const auto &p = parameters_of<Member>(m);
          elastoplastic_update(m.elastic, Member::plastic && m.plasticity_enabled, d_eps, d_spin, state.stress,
                               state.plastic_strain, [&](SymTensor<Real> &trial, const Real eps_p) {
                                 return Member::return_mapping(m.elastic, p, trial, eps_p);
                               });
        }
      else
        for (int c = 0; c < n_voigt; ++c)
          state.stress[c] = Real(NAN);
    });
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

  // The update of a point that knows its whole motion over the step (the MPM step): the
  // material's elastic law picks the Jaumann rate form or Hencky's. all_laws = false leaves
  // Hencky's law out of the compiled code as well (see above).
  template <bool all_laws = true, typename Real>
  MPM_HOST_DEVICE inline void update_stress(const MaterialParameters<Real> &m, const StepKinematics<Real> &k,
                                            MaterialPointState<Real> &state)
  {
    if (disconnected(m, k.J_new)) // no stress, no plastic flow, no state change
      {
        state.stress = SymTensor<Real>::zero();
        return;
      }
    if constexpr (all_laws)
      if (m.elastic_law == ElasticLaw::hencky && m.model != MaterialModel::user_defined)
        {
          with_built_in_model(m.model, [&](auto member) {
            using Member = decltype(member);
            const auto &p = parameters_of<Member>(m);
            hencky_update(m.elastic, Member::plastic && m.plasticity_enabled, k, state.stress, state.plastic_strain,
                          [&](SymTensor<Real> &tau, const Real eps_p) {
                            return Member::return_mapping(m.elastic, p, tau, eps_p);
                          });
          });
          return;
        }
    update_stress<all_laws>(m, k.d_eps, k.d_spin, state);
  }
} // namespace mpm
