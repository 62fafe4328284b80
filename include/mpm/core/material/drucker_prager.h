// Non-associated Drucker-Prager plasticity with a tension cut-off, inner fit to
// Mohr-Coulomb, on the Jaumann hypoelastic update (the formulation of FLAC, Huang et
// al. 2015 and ep2-3De; equations in doc/theory-plasticity.md). Tension positive.
//   f_s = tau + q_phi sigma_m - k_phi      g_s = tau + q_psi sigma_m      (shear)
//   f_t = sigma_m - sigma_t                g_t = sigma_m                  (tension)
//   tau = sqrt(J2), sigma_m = tr(sigma)/3,
//   q_phi = 6 sin phi / (sqrt(3)(3 + sin phi)), k_phi = 6 c cos phi / (sqrt(3)(3 + sin phi)).
// The first candidate is chosen by the mode boundary h = tau - tau_P - alpha_P (sigma_m - sigma_t),
// alpha_P = sqrt(1 + q_phi^2) - q_phi, tau_P = k_phi - q_phi sigma_t. A candidate whose result is not
// admissible (shear return past the cut-off, tension return above tau_P) is replaced by the
// corner return, or by the shear return where the corner would need a negative tension
// multiplier; the result is then the unique solution of the discrete Kuhn-Tucker conditions of
// the two-surface model, for any psi in [0, phi] and any K/G.
// Softening is explicit: strength from eps_p at the start of the increment.
#pragma once

#include <mpm/core/material/linear_elastic.h>
#include <mpm/core/material/softening.h>
#include <mpm/core/small_tensor.h>

#include <cmath>

namespace mpm
{
  template <typename Real>
  struct DruckerPragerParameters
  {
    SofteningStrength<Real> strength;
    // sigma_t [Pa], tension positive; capped at the apex k_phi/q_phi (the default means
    // "at the apex", as in ep2-3De).
    Real tensile_strength = Real(1e30);
  };

  template <typename Real>
  struct DruckerPragerCoefficients
  {
    Real q_phi, k_phi, q_psi;
    Real sigma_t; // effective cut-off, <= apex
    Real tau_P;   // tau on the cone at sigma_m = sigma_t
    Real alpha_P; // slope of the mode boundary h
  };

  template <typename Real>
  MPM_HOST_DEVICE inline DruckerPragerCoefficients<Real>
  drucker_prager_coefficients(const CurrentStrength<Real> &s, const Real tensile_strength)
  {
    DruckerPragerCoefficients<Real> k;
    const Real sqrt3 = std::sqrt(Real(3));
    k.q_phi          = Real(6) * s.sin_phi / (sqrt3 * (Real(3) + s.sin_phi));
    k.k_phi          = Real(6) * s.cohesion * s.cos_phi / (sqrt3 * (Real(3) + s.sin_phi));
    k.q_psi          = Real(6) * s.sin_psi / (sqrt3 * (Real(3) + s.sin_psi));
    k.sigma_t        = tensile_strength;
    if (k.q_phi > Real(0) && k.k_phi / k.q_phi < k.sigma_t)
      k.sigma_t = k.k_phi / k.q_phi;
    k.tau_P   = k.q_phi > Real(0) ? k.k_phi - k.q_phi * k.sigma_t : k.k_phi;
    k.alpha_P = std::sqrt(Real(1) + k.q_phi * k.q_phi) - k.q_phi;
    return k;
  }

  // Host only: the coefficients of the strength (c, phi, psi) and cut-off last asked for
  // by this thread, which are nearly always those of the next point (no softening, one
  // material): the sines, cosine, divisions and root are then not evaluated again. The
  // same values bit for bit, computed by the same function.
  template <typename Real>
  inline DruckerPragerCoefficients<Real> drucker_prager_coefficients_memo(const SoftenedStrength<Real> &t,
                                                                          const Real tensile_strength)
  {
    struct Memo
    {
      bool                            valid;
      Real                            cohesion, phi, psi, tensile_strength;
      DruckerPragerCoefficients<Real> k;
    };
    static thread_local Memo memo{}; // zero-initialised: not valid
    if (!(memo.valid && memo.cohesion == t.cohesion && memo.phi == t.phi && memo.psi == t.psi &&
          memo.tensile_strength == tensile_strength))
      {
        memo.k                = drucker_prager_coefficients(current_strength(t), tensile_strength);
        memo.cohesion         = t.cohesion;
        memo.phi              = t.phi;
        memo.psi              = t.psi;
        memo.tensile_strength = tensile_strength;
        memo.valid            = true;
      }
    return memo.k;
  }

  // The coefficients at plastic strain eps_p.
  template <typename Real>
  MPM_HOST_DEVICE inline DruckerPragerCoefficients<Real>
  drucker_prager_coefficients_at(const DruckerPragerParameters<Real> &dp, const Real eps_p)
  {
#if defined(__CUDA_ARCH__)
    return drucker_prager_coefficients(current_strength(dp.strength, eps_p), dp.tensile_strength);
#else
    return drucker_prager_coefficients_memo(softened_strength(dp.strength, eps_p), dp.tensile_strength);
#endif
  }

  // Return mapping of a trial stress (in: trial, out: admissible stress).
  // multiplier[0]: shear multiplier (of g_s), multiplier[1]: tension multiplier (of g_t).
  // Also evaluated with Real = Dual (consistent_tangent.h).
  template <typename Real>
  MPM_HOST_DEVICE inline ReturnResult<Real> drucker_prager_return(const LinearElasticParameters<Real>   &elastic,
                                                                  const DruckerPragerCoefficients<Real> &k,
                                                                  SymTensor<Real>                       &stress)
  {
    using std::sqrt; // and mpm::sqrt of a Dual (consistent_tangent.h)
    const Real K   = elastic.bulk_modulus();
    const Real G   = elastic.shear_modulus();
    const Real p   = mean_stress(stress);
    const Real tau = sqrt(second_deviatoric_invariant(stress));
    const Real f_s = tau + k.q_phi * p - k.k_phi;
    const Real x   = p - k.sigma_t; // f_t
    const Real y   = tau - k.tau_P;
    if (f_s <= Real(0) && x <= Real(0))
      return elastic_return<Real>();

    // Candidate: shear (s), tension (t) or corner (c).
    enum { s_mode, t_mode, c_mode } mode;
    const Real h = y - k.alpha_P * x;
    if (x < Real(0) || h > Real(0))
      mode = s_mode;
    else
      mode = y <= Real(0) ? t_mode : c_mode;
    // Admissibility: the shear return stays below the cut-off iff x/K <= q_psi y/G, which is
    // also the condition for a negative tension multiplier at the corner.
    if (x >= Real(0) && y > Real(0))
      mode = x * G > k.q_psi * y * K ? c_mode : s_mode;

    Real p_new, tau_new, mu_s, mu_t;
    if (mode == s_mode)
      {
        mu_s    = f_s / (G + K * k.q_phi * k.q_psi);
        mu_t    = Real(0);
        p_new   = p - K * k.q_psi * mu_s;
        tau_new = k.k_phi - k.q_phi * p_new;
      }
    else if (mode == t_mode)
      {
        mu_s    = Real(0);
        mu_t    = x / K;
        p_new   = k.sigma_t;
        tau_new = tau;
      }
    else
      {
        mu_s    = y / G;
        mu_t    = x / K - k.q_psi * mu_s;
        p_new   = k.sigma_t;
        tau_new = k.tau_P;
      }
    if (tau_new < Real(0))
      tau_new = Real(0);

    const Real ratio = tau > Real(0) ? tau_new / tau : Real(0);
    for (int i = 0; i < 3; ++i)
      stress[i] = (stress[i] - p) * ratio + p_new;
    for (int i = 3; i < n_voigt; ++i)
      stress[i] *= ratio;

    ReturnResult<Real> r;
    r.mode          = mode == s_mode ? ReturnMode::shear : (mode == t_mode ? ReturnMode::tension : ReturnMode::corner);
    r.multiplier[0] = mu_s;
    r.multiplier[1] = mu_t;
    // d_eps^p = mu_s (s/(2 tau) + q_psi/3 I) + mu_t/3 I: deviatoric norm^2 mu_s^2/2, volumetric v^2/3.
    const Real v       = mu_s * k.q_psi + mu_t;
    r.d_plastic_strain = sqrt(mu_s * mu_s / Real(3) + Real(2) * v * v / Real(9));
    return r;
  }

  // Jaumann rotation, elastic trial, return mapping, explicit softening.
  template <typename Real>
  MPM_HOST_DEVICE inline ReturnResult<Real> drucker_prager_update(const LinearElasticParameters<Real> &elastic,
                                                                  const DruckerPragerParameters<Real> &dp,
                                                                  const bool             plasticity_enabled,
                                                                  const SymTensor<Real> &d_eps,
                                                                  const Mat3<Real>      &d_spin,
                                                                  SymTensor<Real>       &stress,
                                                                  Real                  &plastic_strain)
  {
    return elastoplastic_update(elastic, plasticity_enabled, d_eps, d_spin, stress, plastic_strain,
                                [&](SymTensor<Real> &trial, const Real eps_p) {
                                  return drucker_prager_return(elastic, drucker_prager_coefficients_at(dp, eps_p),
                                                               trial);
                                });
  }
} // namespace mpm
