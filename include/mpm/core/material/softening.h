// Strength parameters shared by the frictional plasticity models (Drucker-Prager,
// Mohr-Coulomb) and their softening with the accumulated equivalent plastic strain
// eps_p (see doc/theory-plasticity.md):
//   c(eps_p)   = max(c_res, c_peak - H eps_p)                         (linear cohesion softening)
//   phi(eps_p) = phi_peak + (phi_res - phi_peak) min(1, eps_p / eps_phi)  (optional friction softening)
//   psi        = min(psi, phi(eps_p))                                  (dilatancy never exceeds friction)
// Angles are in radians here; the prm layer converts from degrees.
#pragma once

#include <mpm/core/config.h>
#include <mpm/core/material/linear_elastic.h>

#include <cmath>

namespace mpm
{
  template <typename Real>
  struct SofteningStrength
  {
    Real cohesion                  = Real(0); // c_peak [Pa]
    Real residual_cohesion         = Real(0); // c_res [Pa], <= c_peak
    Real softening_modulus         = Real(0); // H [Pa per unit eps_p], >= 0; 0: no cohesion softening
    Real friction_angle            = Real(0); // phi_peak [rad]
    Real residual_friction_angle   = Real(0); // phi_res [rad]; equal to phi_peak: no friction softening
    Real friction_softening_strain = Real(0); // eps_phi where phi reaches phi_res; <= 0: the strain at which
                                              // c reaches c_res, (c_peak - c_res)/H; no softening if neither
    Real dilatancy_angle           = Real(0); // psi [rad], 0 <= psi <= phi
  };

  // The strength at one plastic strain, as the return mappings use it.
  template <typename Real>
  struct CurrentStrength
  {
    Real cohesion;
    Real sin_phi, cos_phi;
    Real sin_psi;
  };

  template <typename Real>
  MPM_HOST_DEVICE inline Real softened_cohesion(const SofteningStrength<Real> &s, const Real eps_p)
  {
    const Real c = s.cohesion - s.softening_modulus * eps_p;
    return c > s.residual_cohesion ? c : s.residual_cohesion;
  }

  template <typename Real>
  MPM_HOST_DEVICE inline Real softened_friction_angle(const SofteningStrength<Real> &s, const Real eps_p)
  {
    Real eps_phi = s.friction_softening_strain;
    if (!(eps_phi > Real(0)) && s.softening_modulus > Real(0) && s.cohesion > s.residual_cohesion)
      eps_phi = (s.cohesion - s.residual_cohesion) / s.softening_modulus;
    if (!(eps_phi > Real(0)))
      return s.friction_angle;
    const Real xi = eps_p < eps_phi ? eps_p / eps_phi : Real(1);
    return s.friction_angle + (s.residual_friction_angle - s.friction_angle) * xi;
  }

  // Cohesion and angles at one plastic strain (psi capped at phi).
  template <typename Real>
  struct SoftenedStrength
  {
    Real cohesion, phi, psi;
  };

  template <typename Real>
  MPM_HOST_DEVICE inline SoftenedStrength<Real> softened_strength(const SofteningStrength<Real> &s, const Real eps_p)
  {
    SoftenedStrength<Real> r;
    r.phi      = softened_friction_angle(s, eps_p);
    r.psi      = s.dilatancy_angle < r.phi ? s.dilatancy_angle : r.phi;
    r.cohesion = softened_cohesion(s, eps_p);
    return r;
  }

  template <typename Real>
  MPM_HOST_DEVICE inline CurrentStrength<Real> current_strength(const SoftenedStrength<Real> &t)
  {
    CurrentStrength<Real> r;
    r.cohesion = t.cohesion;
    r.sin_phi  = std::sin(t.phi);
    r.cos_phi  = std::cos(t.phi);
    r.sin_psi  = std::sin(t.psi);
    return r;
  }

  template <typename Real>
  MPM_HOST_DEVICE inline CurrentStrength<Real> current_strength(const SofteningStrength<Real> &s, const Real eps_p)
  {
    return current_strength(softened_strength(s, eps_p));
  }

  // What a return mapping did; the tests read it, the step ignores it.
  enum class ReturnMode : int
  {
    elastic = 0,
    shear,          // DP cone / MC plane
    tension,        // DP tension cut-off plane
    corner,         // DP: cone and tension plane together
    edge_extension, // MC: sigma_2 = sigma_3 edge (triaxial extension meridian), tension positive
    edge_compression, // MC: sigma_1 = sigma_2 edge (triaxial compression meridian), tension positive
    apex            // MC apex, sigma = c cot(phi) 1
  };

  template <typename Real>
  struct ReturnResult
  {
    ReturnMode mode;
    Real       multiplier[2];     // plastic multipliers of the active surfaces (see each model)
    Real       d_plastic_strain;  // increment of eps_p = sqrt(2/3 d_eps^p : d_eps^p)
  };

  template <typename Real>
  MPM_HOST_DEVICE inline ReturnResult<Real> elastic_return()
  {
    ReturnResult<Real> r;
    r.mode          = ReturnMode::elastic;
    r.multiplier[0] = r.multiplier[1] = Real(0);
    r.d_plastic_strain                = Real(0);
    return r;
  }

  // The frame every plastic model shares: Jaumann rotation and elastic trial, then (unless
  // in the elastic-loading phase) the model's return mapping with the strength at the
  // start-of-step plastic strain (explicit softening), then eps_p += d eps_p.
  template <typename Real, typename ReturnMapping>
  MPM_HOST_DEVICE inline ReturnResult<Real> elastoplastic_update(const LinearElasticParameters<Real> &elastic,
                                                                 const bool             plasticity_enabled,
                                                                 const SymTensor<Real> &d_eps,
                                                                 const Mat3<Real>      &d_spin,
                                                                 SymTensor<Real>       &stress,
                                                                 Real                  &plastic_strain,
                                                                 ReturnMapping        &&return_mapping)
  {
    linear_elastic_update(elastic, d_eps, d_spin, stress);
    if (!plasticity_enabled)
      return elastic_return<Real>();
    const ReturnResult<Real> r = return_mapping(stress, plastic_strain);
    plastic_strain += r.d_plastic_strain;
    return r;
  }

  // The strength in another floating-point type (precision.h).
  template <typename To, typename From>
  inline SofteningStrength<To> converted(const SofteningStrength<From> &s)
  {
    static_assert(sizeof(SofteningStrength<From>) == 7 * sizeof(From), "a field of SofteningStrength is not copied");
    SofteningStrength<To> r;
    r.cohesion                  = static_cast<To>(s.cohesion);
    r.residual_cohesion         = static_cast<To>(s.residual_cohesion);
    r.softening_modulus         = static_cast<To>(s.softening_modulus);
    r.friction_angle            = static_cast<To>(s.friction_angle);
    r.residual_friction_angle   = static_cast<To>(s.residual_friction_angle);
    r.friction_softening_strain = static_cast<To>(s.friction_softening_strain);
    r.dilatancy_angle           = static_cast<To>(s.dilatancy_angle);
    return r;
  }

  // The strength divided by a strength reduction factor F (strength_reduction.h).
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
} // namespace mpm
