// The consistent (algorithmic) tangent of the small-strain elasto-plastic update that the
// implicit FEM stage needs for Newton's method (issue 14):
//   sigma_new(d_eps) = return_mapping(sigma_old + D d_eps),   C = d sigma_new / d d_eps.
// The return mappings are the ones the MPM steps with (drucker_prager.h, mohr_coulomb.h),
// evaluated with forward-mode dual numbers (dual.h), so C is the derivative of exactly the
// algorithm that gives the stress, every return region included (cone, tension cut-off,
// corner; Mohr-Coulomb plane, edges, apex), with no derivation by hand to keep in step.
// Mohr-Coulomb returns in principal space: the duals give d sigma_i / d sigma_trial_j there,
// and the derivative of the isotropic tensor function adds the rotation of the principal
// directions, (sigma_i - sigma_j) / (trial_i - trial_j), with its limit where two trial
// principal stresses coincide (de Souza Neto et al. 2008, appendix A).
//
// Convention: Voigt order xx, yy, zz, xy, yz, xz for stress and strain, the strain with tensor
// shear components (eps_xy, not gamma_xy) as everywhere in the core: C[i][j] is the change of
// sigma_i when the strain component j (and its symmetric partner) grows by one, so an elastic
// material has C[3][3] = 2 G. Strength is that at the start of the increment (explicit
// softening, as in the MPM).
#pragma once

#include <mpm/core/dual.h>
#include <mpm/core/material/drucker_prager.h>
#include <mpm/core/material/linear_elastic.h>
#include <mpm/core/material/mohr_coulomb.h>
#include <mpm/core/material/symmetric_eigen.h>
#include <mpm/core/small_tensor.h>

#include <cmath>

namespace mpm
{
  using Tangent = double[n_voigt][n_voigt];

  namespace tangent_detail
  {
    // Voigt component c as the entry (row[c], col[c]) of the 3x3 tensor.
    constexpr int row[n_voigt] = {0, 1, 2, 0, 1, 0};
    constexpr int col[n_voigt] = {0, 1, 2, 1, 2, 2};

    // D: column j is the stress of a unit strain component j.
    MPM_HOST_DEVICE inline void elastic_matrix(const LinearElasticParameters<double> &e, Tangent D)
    {
      for (int j = 0; j < n_voigt; ++j)
        {
          SymTensor<double> unit = SymTensor<double>::zero();
          unit[j]                = 1;
          const SymTensor<double> column = elastic_stress_increment(e, unit);
          for (int i = 0; i < n_voigt; ++i)
            D[i][j] = column[i];
        }
    }

    // C = A D, A = d sigma_new / d sigma_trial.
    MPM_HOST_DEVICE inline void times_elastic(const Tangent A, const LinearElasticParameters<double> &e, Tangent C)
    {
      Tangent D;
      elastic_matrix(e, D);
      for (int i = 0; i < n_voigt; ++i)
        for (int j = 0; j < n_voigt; ++j)
          {
            C[i][j] = 0;
            for (int k = 0; k < n_voigt; ++k)
              C[i][j] += A[i][k] * D[k][j];
          }
    }

    template <int N>
    MPM_HOST_DEVICE inline LinearElasticParameters<Dual<N>> constant(const LinearElasticParameters<double> &e)
    {
      return {Dual<N>(e.youngs_modulus), Dual<N>(e.poissons_ratio)};
    }
  } // namespace tangent_detail

  // The elastic tangent D.
  MPM_HOST_DEVICE inline void elastic_tangent(const LinearElasticParameters<double> &elastic, Tangent C)
  {
    tangent_detail::elastic_matrix(elastic, C);
  }

  // A return mapping of the whole Voigt stress, return_mapping(elastic, stress) with both in
  // Dual<6>: returns the trial stress (in: trial, out: returned, as the mapping gives it) and
  // its tangent C with respect to the strain increment. Host only (the FEM stage).
  template <typename ReturnMapping>
  inline ReturnResult<double> voigt_tangent(const LinearElasticParameters<double> &elastic,
                                                            SymTensor<double> &stress, Tangent C,
                                                            ReturnMapping &&return_mapping)
  {
    using D6 = Dual<n_voigt>;
    SymTensor<D6> s;
    for (int c = 0; c < n_voigt; ++c)
      s[c] = D6::variable(stress[c], c);
    const ReturnResult<D6> r = return_mapping(tangent_detail::constant<n_voigt>(elastic), s);
    Tangent A;
    for (int i = 0; i < n_voigt; ++i)
      {
        stress[i] = s[i].value;
        for (int j = 0; j < n_voigt; ++j)
          A[i][j] = s[i].derivative[j];
      }
    tangent_detail::times_elastic(A, elastic, C);
    return {r.mode, {r.multiplier[0].value, r.multiplier[1].value}, r.d_plastic_strain.value};
  }

  // Drucker-Prager: voigt_tangent of drucker_prager_return.
  inline ReturnResult<double> drucker_prager_tangent(const LinearElasticParameters<double>   &elastic,
                                                     const DruckerPragerCoefficients<double> &k,
                                                     SymTensor<double> &stress, Tangent C)
  {
    using D6 = Dual<n_voigt>;
    const DruckerPragerCoefficients<D6> kd{k.q_phi, k.k_phi, k.q_psi, k.sigma_t, k.tau_P, k.alpha_P};
    return voigt_tangent(elastic, stress, C, [&](const LinearElasticParameters<D6> &e, SymTensor<D6> &s) {
      return drucker_prager_return(e, kd, s);
    });
  }

  // Mohr-Coulomb: the same for mohr_coulomb_return.
  MPM_HOST_DEVICE inline ReturnResult<double> mohr_coulomb_tangent(const LinearElasticParameters<double> &elastic,
                                                                   const CurrentStrength<double>         &strength,
                                                                   SymTensor<double> &stress, Tangent C)
  {
    using namespace tangent_detail;
    using D3 = Dual<3>;
    double       trial[3];
    Mat3<double> V;
    symmetric_eigen(stress, trial, V);
    D3 sigma[3];
    for (int i = 0; i < 3; ++i)
      sigma[i] = D3::variable(trial[i], i);
    const CurrentStrength<D3> sd{strength.cohesion, strength.sin_phi, strength.cos_phi, strength.sin_psi};
    const ReturnResult<D3>    r = mohr_coulomb_return_principal(constant<3>(elastic), sd, sigma);
    if (r.mode == ReturnMode::elastic)
      {
        elastic_tangent(elastic, C);
        return elastic_return<double>();
      }

    // a[i][j] = d sigma_i / d trial_j; rotation terms theta[i][j] (i != j).
    double a[3][3], theta[3][3] = {};
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j)
        a[i][j] = sigma[i].derivative[j];
    const double scale = std::abs(trial[0]) + std::abs(trial[1]) + std::abs(trial[2]) + strength.cohesion;
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j)
        if (i != j)
          theta[i][j] = std::abs(trial[i] - trial[j]) > 1e-10 * scale ?
                          (sigma[i].value - sigma[j].value) / (trial[i] - trial[j]) :
                          a[i][i] - a[i][j]; // the limit at coinciding trial principal stresses

    // A: column c is d sigma for the trial perturbation E_c (Voigt component c and its partner).
    Tangent A;
    for (int c = 0; c < n_voigt; ++c)
      {
        // p[i][j] = v_i . E_c v_j
        double p[3][3];
        for (int i = 0; i < 3; ++i)
          for (int j = 0; j < 3; ++j)
            p[i][j] = V.a[row[c]][i] * V.a[col[c]][j] + (row[c] != col[c] ? V.a[col[c]][i] * V.a[row[c]][j] : 0.0);
        double dsigma[3][3] = {};
        for (int i = 0; i < 3; ++i)
          for (int j = 0; j < 3; ++j)
            {
              // principal part: sum_ij a_ij p_jj v_i v_i^T; rotation: theta_ij p_ij v_i v_j^T
              const double weight = i == j ? 0.0 : theta[i][j] * p[i][j];
              double       principal = 0;
              if (i == j)
                for (int k = 0; k < 3; ++k)
                  principal += a[i][k] * p[k][k];
              for (int m = 0; m < 3; ++m)
                for (int n = 0; n < 3; ++n)
                  dsigma[m][n] += (principal + weight) * V.a[m][i] * V.a[n][j];
            }
        for (int out = 0; out < n_voigt; ++out)
          A[out][c] = dsigma[row[out]][col[out]];
      }
    times_elastic(A, elastic, C);

    // The stress as mohr_coulomb_return gives it.
    double correction[3];
    for (int i = 0; i < 3; ++i)
      correction[i] = trial[i] - sigma[i].value;
    const SymTensor<double> d = from_principal(correction, V);
    for (int c = 0; c < n_voigt; ++c)
      stress[c] -= d[c];
    return {r.mode, {r.multiplier[0].value, r.multiplier[1].value}, r.d_plastic_strain.value};
  }
} // namespace mpm
