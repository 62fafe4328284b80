// Finite-strain elasticity and plasticity in principal logarithmic strains (Hencky), the
// alternative to the Jaumann rate form (doc/theory-plasticity.md, "Hencky"):
//   tau = J sigma = lambda tr(eps_e) I + 2 G eps_e,   eps_e = ln V_e = ln(b_e) / 2,
// with b_e = F_e F_e^T the elastic left Cauchy-Green tensor. A step updates b_e by the
// increment's relative deformation gradient f = I + L dt (b_e_trial = f b_e f^T), takes its
// logarithm in principal axes, and returns the trial Kirchhoff stress to the yield surface
// with the models' own return mappings: for isotropic elasticity and plasticity the return in
// principal logarithmic strains has exactly the form of the small-strain one (exponential
// map). b_e is not stored: Hencky's law is invertible, so the point's stress gives it back
// (eps_e = C^-1 : tau, coaxial with tau). No extra field per point; two symmetric eigen
// decompositions per point and step.
#pragma once

#include <mpm/core/material/linear_elastic.h>
#include <mpm/core/material/symmetric_eigen.h>
#include <mpm/core/small_tensor.h>

#include <cmath>

namespace mpm
{
  // How the elastic part of a model relates stress and deformation.
  enum class ElasticLaw : int
  {
    jaumann_rate = 0, // hypoelastic: sigma_{n+1} = Q sigma_n Q^T + C : d_eps (the default)
    hencky       = 1  // hyperelastic in logarithmic strain, plasticity multiplicative
  };

  // The motion of a point over one step, as a model needs it.
  template <typename Real>
  struct StepKinematics
  {
    SymTensor<Real> d_eps;  // sym(L) dt
    Mat3<Real>      d_spin; // skew(L) dt
    Mat3<Real>      f;      // I + L dt (plane strain: f_zz = 1)
    Real            J;      // det F at the start of the step (the volume ratio V / V0)
    Real            J_new;  // at its end: J det f, or J where the points hold their place
  };

  // The elastic logarithmic strain of a Kirchhoff stress: eps_e = C^-1 : tau, per principal value.
  template <typename Real>
  MPM_HOST_DEVICE inline void hencky_strain_of(const LinearElasticParameters<Real> &p, const Real tau[3], Real eps[3])
  {
    const Real E = p.youngs_modulus, nu = p.poissons_ratio;
    const Real tr = tau[0] + tau[1] + tau[2];
    for (int k = 0; k < 3; ++k)
      eps[k] = ((Real(1) + nu) * tau[k] - nu * tr) / E;
  }

  // Kirchhoff stress of an elastic logarithmic strain, per principal value.
  template <typename Real>
  MPM_HOST_DEVICE inline void hencky_stress_of(const LinearElasticParameters<Real> &p, const Real eps[3], Real tau[3])
  {
    const Real G      = p.shear_modulus();
    const Real lambda = p.bulk_modulus() - Real(2) / Real(3) * G;
    const Real tr     = eps[0] + eps[1] + eps[2];
    for (int k = 0; k < 3; ++k)
      tau[k] = lambda * tr + Real(2) * G * eps[k];
  }

  // The elastic trial Kirchhoff stress of a step from the Cauchy stress at its start:
  // b_e from sigma (through tau = J sigma), pushed forward by f, back to a stress.
  template <typename Real>
  MPM_HOST_DEVICE inline SymTensor<Real> hencky_trial_kirchhoff(const LinearElasticParameters<Real> &p,
                                                                const SymTensor<Real>               &sigma,
                                                                const StepKinematics<Real>          &k)
  {
    SymTensor<Real> tau;
    for (int c = 0; c < n_voigt; ++c)
      tau[c] = k.J * sigma[c];
    Real       values[3], eps[3];
    Mat3<Real> axes;
    symmetric_eigen(tau, values, axes);
    hencky_strain_of(p, values, eps);
    for (int a = 0; a < 3; ++a)
      values[a] = std::exp(Real(2) * eps[a]);
    const Mat3<Real> b       = to_matrix(from_principal(values, axes));
    const Mat3<Real> b_trial = multiply(multiply(k.f, b), transpose(k.f));
    SymTensor<Real>  b_sym;
    const int        row[6] = {0, 1, 2, 0, 1, 0}, col[6] = {0, 1, 2, 1, 2, 2};
    for (int c = 0; c < n_voigt; ++c)
      b_sym[c] = Real(0.5) * (b_trial.a[row[c]][col[c]] + b_trial.a[col[c]][row[c]]);
    symmetric_eigen(b_sym, values, axes);
    for (int a = 0; a < 3; ++a)
      eps[a] = Real(0.5) * std::log(values[a]);
    hencky_stress_of(p, eps, values);
    return from_principal(values, axes);
  }

  // Hencky elasticity, then the model's return mapping (return_mapping(tau, eps_p), as in
  // elastoplastic_update) on the Kirchhoff stress; the Cauchy stress is tau / J_new.
  template <typename Real, typename ReturnMapping>
  MPM_HOST_DEVICE inline void hencky_update(const LinearElasticParameters<Real> &elastic, const bool plasticity_enabled,
                                            const StepKinematics<Real> &k, SymTensor<Real> &stress,
                                            Real &plastic_strain, ReturnMapping &&return_mapping)
  {
    SymTensor<Real> tau = hencky_trial_kirchhoff(elastic, stress, k);
    if (plasticity_enabled)
      plastic_strain += return_mapping(tau, plastic_strain).d_plastic_strain;
    for (int c = 0; c < n_voigt; ++c)
      stress[c] = tau[c] / k.J_new;
  }
} // namespace mpm
