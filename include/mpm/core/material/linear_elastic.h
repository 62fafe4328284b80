// Linear elastic material, hypoelastic in rate form with the Jaumann stress rate
// (updated Lagrangian): sigma_{n+1} = Q sigma_n Q^T + C : d_eps.
#pragma once

#include <mpm/core/material/objective_rotation.h>
#include <mpm/core/small_tensor.h>

namespace mpm
{
  template <typename Real>
  struct LinearElasticParameters
  {
    Real youngs_modulus;
    Real poissons_ratio;

    MPM_HOST_DEVICE Real shear_modulus() const
    {
      return youngs_modulus / (Real(2) * (Real(1) + poissons_ratio));
    }
    MPM_HOST_DEVICE Real bulk_modulus() const
    {
      return youngs_modulus / (Real(3) * (Real(1) - Real(2) * poissons_ratio));
    }
    // Constrained (P-wave) modulus K + 4G/3: sets the elastic wave speed for the CFL condition.
    MPM_HOST_DEVICE Real p_wave_modulus() const
    {
      return bulk_modulus() + Real(4) / Real(3) * shear_modulus();
    }
  };

  // Isotropic Hooke's law applied to a strain increment (engineering shear = 2 * tensor shear).
  template <typename Real>
  MPM_HOST_DEVICE inline SymTensor<Real> elastic_stress_increment(const LinearElasticParameters<Real> &p,
                                                                  const SymTensor<Real> &d_eps)
  {
    const Real G      = p.shear_modulus();
    const Real lambda = p.bulk_modulus() - Real(2) / Real(3) * G;
    const Real tr     = trace(d_eps);
    SymTensor<Real> ds;
    for (int i = 0; i < 3; ++i)
      ds[i] = lambda * tr + Real(2) * G * d_eps[i];
    for (int i = 3; i < 6; ++i)
      ds[i] = Real(2) * G * d_eps[i];
    return ds;
  }

  template <typename Real>
  MPM_HOST_DEVICE inline void linear_elastic_update(const LinearElasticParameters<Real> &p,
                                                    const SymTensor<Real> &d_eps,
                                                    const Mat3<Real>      &d_spin,
                                                    SymTensor<Real>       &stress)
  {
    const SymTensor<Real> rotated = rotate_jaumann(stress, d_spin);
    const SymTensor<Real> ds      = elastic_stress_increment(p, d_eps);
    for (int i = 0; i < n_voigt; ++i)
      stress[i] = rotated[i] + ds[i];
  }
} // namespace mpm
