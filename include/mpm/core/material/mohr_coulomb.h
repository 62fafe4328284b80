// Non-associated Mohr-Coulomb plasticity in 3D on the Jaumann hypoelastic update.
// Return mapping in principal stress space (de Souza Neto et al. 2008, Box 8.4-8.5;
// Clausen et al. 2006): plane, edge and apex returns. Tension positive, principal
// stresses sorted sigma_1 >= sigma_2 >= sigma_3 (sigma_3 the most compressive):
//   f = (sigma_1 - sigma_3) + (sigma_1 + sigma_3) sin phi - 2 c cos phi
//   g = (sigma_1 - sigma_3) + (sigma_1 + sigma_3) sin psi
// Isotropic elasticity keeps the principal directions of the trial stress; the stress is
// rebuilt with them. Softening is explicit: strength from eps_p at the start of the increment.
// Equations and the validity checks that select plane / edge / apex: doc/theory-plasticity.md.
#pragma once

#include <mpm/core/material/linear_elastic.h>
#include <mpm/core/material/softening.h>
#include <mpm/core/material/symmetric_eigen.h>
#include <mpm/core/small_tensor.h>

#include <cmath>

namespace mpm
{
  template <typename Real>
  struct MohrCoulombParameters
  {
    SofteningStrength<Real> strength;
  };

  namespace mohr_coulomb_detail
  {
    template <typename Real>
    MPM_HOST_DEVICE inline Real dot3(const Real a[3], const Real b[3])
    {
      return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    }

    // Principal-space isotropic stiffness applied to b: lambda (b.1) 1 + 2 G b.
    template <typename Real>
    MPM_HOST_DEVICE inline void stiffness(const Real lambda, const Real G, const Real b[3], Real out[3])
    {
      const Real tr = b[0] + b[1] + b[2];
      for (int i = 0; i < 3; ++i)
        out[i] = lambda * tr + Real(2) * G * b[i];
    }

    template <typename Real>
    MPM_HOST_DEVICE inline bool ordered(const Real s[3], const Real tol)
    {
      return s[0] >= s[1] - tol && s[1] >= s[2] - tol;
    }
  } // namespace mohr_coulomb_detail

  // Yield function on sorted principal stresses.
  template <typename Real>
  MPM_HOST_DEVICE inline Real mohr_coulomb_yield(const CurrentStrength<Real> &s, const Real sigma[3])
  {
    return (sigma[0] - sigma[2]) + (sigma[0] + sigma[2]) * s.sin_phi - Real(2) * s.cohesion * s.cos_phi;
  }

  // Return mapping on sorted principal trial stresses (in: trial, out: returned, sorted).
  // Also evaluated with Real = Dual (consistent_tangent.h).
  // multiplier: plane (dl, 0); edges (dl_1, dl_2) of f_1 and of the neighbouring plane;
  // apex (volumetric plastic strain, 0).
  template <typename Real>
  MPM_HOST_DEVICE inline ReturnResult<Real> mohr_coulomb_return_principal(const LinearElasticParameters<Real> &elastic,
                                                                          const CurrentStrength<Real>         &s,
                                                                          Real sigma[3])
  {
    using namespace mohr_coulomb_detail;
    using std::abs; // and mpm::abs, mpm::sqrt of a Dual (consistent_tangent.h)
    using std::sqrt;
    const Real f1 = mohr_coulomb_yield(s, sigma);
    if (f1 <= Real(0))
      return elastic_return<Real>();

    const Real K = elastic.bulk_modulus(), G = elastic.shear_modulus();
    const Real lambda = K - Real(2) / Real(3) * G;
    const Real sf = s.sin_phi, sp = s.sin_psi;
    const Real strength = Real(2) * s.cohesion * s.cos_phi;
    const Real scale = abs(sigma[0]) + abs(sigma[1]) + abs(sigma[2]) + s.cohesion;
    const Real tol   = Real(sizeof(Real) == 4 ? 1e-5 : 1e-13) * scale;

    const Real a1[3] = {Real(1) + sf, Real(0), -(Real(1) - sf)};
    const Real b1[3] = {Real(1) + sp, Real(0), -(Real(1) - sp)};
    Real Db1[3];
    stiffness(lambda, G, b1, Db1);

    ReturnResult<Real> r;
    // 1. plane
    {
      const Real dl = f1 / dot3(a1, Db1);
      Real       t[3];
      for (int i = 0; i < 3; ++i)
        t[i] = sigma[i] - dl * Db1[i];
      if (ordered(t, tol))
        {
          for (int i = 0; i < 3; ++i)
            sigma[i] = t[i];
          r.mode          = ReturnMode::shear;
          r.multiplier[0] = dl;
          r.multiplier[1] = Real(0);
          Real e[3]       = {dl * b1[0], dl * b1[1], dl * b1[2]};
          r.d_plastic_strain = sqrt(Real(2) / Real(3) * dot3(e, e));
          return r;
        }
      // 2. edges: the one on the side the plane return overshot first.
      const bool compression_first = t[0] < t[1];
      for (int attempt = 0; attempt < 2; ++attempt)
        {
          const bool compression = (attempt == 0) == compression_first;
          // compression edge sigma_1 = sigma_2: plane (2,3); extension edge sigma_2 = sigma_3: plane (1,2)
          const Real a2[3] = {compression ? Real(0) : Real(1) + sf,
                              compression ? Real(1) + sf : -(Real(1) - sf),
                              compression ? -(Real(1) - sf) : Real(0)};
          const Real b2[3] = {compression ? Real(0) : Real(1) + sp,
                              compression ? Real(1) + sp : -(Real(1) - sp),
                              compression ? -(Real(1) - sp) : Real(0)};
          Real Db2[3];
          stiffness(lambda, G, b2, Db2);
          const Real f2  = dot3(a2, sigma) - strength;
          const Real m11 = dot3(a1, Db1), m12 = dot3(a1, Db2), m21 = dot3(a2, Db1), m22 = dot3(a2, Db2);
          const Real det = m11 * m22 - m12 * m21;
          const Real dl1 = (f1 * m22 - m12 * f2) / det;
          const Real dl2 = (m11 * f2 - m21 * f1) / det;
          for (int i = 0; i < 3; ++i)
            t[i] = sigma[i] - dl1 * Db1[i] - dl2 * Db2[i];
          const Real dl_tol = tol / G;
          if (dl1 >= -dl_tol && dl2 >= -dl_tol && ordered(t, tol))
            {
              // put the two equal stresses exactly equal
              if (compression)
                t[0] = t[1] = Real(0.5) * (t[0] + t[1]);
              else
                t[1] = t[2] = Real(0.5) * (t[1] + t[2]);
              for (int i = 0; i < 3; ++i)
                sigma[i] = t[i];
              r.mode          = compression ? ReturnMode::edge_compression : ReturnMode::edge_extension;
              r.multiplier[0] = dl1;
              r.multiplier[1] = dl2;
              Real e[3];
              for (int i = 0; i < 3; ++i)
                e[i] = dl1 * b1[i] + dl2 * b2[i];
              r.d_plastic_strain = sqrt(Real(2) / Real(3) * dot3(e, e));
              return r;
            }
          if (!(sf > Real(0)) && attempt == 1) // no apex without friction: keep the edge result
            {
              for (int i = 0; i < 3; ++i)
                sigma[i] = t[i];
              r.mode          = compression ? ReturnMode::edge_compression : ReturnMode::edge_extension;
              r.multiplier[0] = dl1;
              r.multiplier[1] = dl2;
              Real e[3];
              for (int i = 0; i < 3; ++i)
                e[i] = dl1 * b1[i] + dl2 * b2[i];
              r.d_plastic_strain = sqrt(Real(2) / Real(3) * dot3(e, e));
              return r;
            }
        }
    }
    // 3. apex sigma = c cot(phi) 1
    const Real apex = s.cohesion * s.cos_phi / sf;
    Real       e[3];
    const Real dp = (sigma[0] + sigma[1] + sigma[2]) / Real(3) - apex;
    for (int i = 0; i < 3; ++i)
      {
        const Real d = sigma[i] - apex;
        e[i]         = (d - dp) / (Real(2) * G) + dp / (Real(3) * K);
        sigma[i]     = apex;
      }
    r.mode             = ReturnMode::apex;
    r.multiplier[0]    = e[0] + e[1] + e[2];
    r.multiplier[1]    = Real(0);
    r.d_plastic_strain = sqrt(Real(2) / Real(3) * dot3(e, e));
    return r;
  }

  // Return mapping of a full trial stress tensor (in: trial, out: returned).
  template <typename Real>
  MPM_HOST_DEVICE inline ReturnResult<Real> mohr_coulomb_return(const LinearElasticParameters<Real> &elastic,
                                                                const CurrentStrength<Real>         &s,
                                                                SymTensor<Real>                     &stress)
  {
    Real       trial[3], sigma[3];
    Mat3<Real> V;
    symmetric_eigen(stress, trial, V);
    for (int i = 0; i < 3; ++i)
      sigma[i] = trial[i];
    const ReturnResult<Real> r = mohr_coulomb_return_principal(elastic, s, sigma);
    if (r.mode == ReturnMode::elastic)
      return r;
    // sigma = sigma_trial - sum_k (trial_k - sigma_k) v_k v_k^T: exact where nothing changes
    Real correction[3];
    for (int i = 0; i < 3; ++i)
      correction[i] = trial[i] - sigma[i];
    const SymTensor<Real> d = from_principal(correction, V);
    for (int c = 0; c < n_voigt; ++c)
      stress[c] -= d[c];
    return r;
  }

  // Jaumann rotation, elastic trial, return mapping, explicit softening.
  template <typename Real>
  MPM_HOST_DEVICE inline ReturnResult<Real> mohr_coulomb_update(const LinearElasticParameters<Real> &elastic,
                                                                const MohrCoulombParameters<Real>   &mc,
                                                                const bool             plasticity_enabled,
                                                                const SymTensor<Real> &d_eps,
                                                                const Mat3<Real>      &d_spin,
                                                                SymTensor<Real>       &stress,
                                                                Real                  &plastic_strain)
  {
    return elastoplastic_update(elastic, plasticity_enabled, d_eps, d_spin, stress, plastic_strain,
                                [&](SymTensor<Real> &trial, const Real eps_p) {
                                  return mohr_coulomb_return(elastic, current_strength(mc.strength, eps_p), trial);
                                });
  }
} // namespace mpm
