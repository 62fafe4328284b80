// "test von mises": J2 plasticity without hardening (the von Mises cone's limit, a phi = 0
// total-stress model), owned by the tests: it shows that a device-capable material is this one
// file and one line in material_family.h (tests/core/test_material_family.cc,
// tests/gpu/test_gpu_cpu_agreement.cu). Radial return: the deviator of a trial stress with
// q = sqrt(3 J2) above the yield stress sigma_y is scaled back to q = sigma_y, and the
// equivalent plastic strain grows by (q - sigma_y) / 3G.
#pragma once

#include <mpm/core/material/models/model_traits.h>

namespace mpm
{
  template <typename Real>
  struct TestVonMisesParameters
  {
    Real yield_stress = Real(1e30); // sigma_y [Pa]
  };

  struct TestVonMisesModel
  {
    template <typename Real>
    using Parameters = TestVonMisesParameters<Real>;

    static constexpr const char   *name                = "test von mises";
    static constexpr const char   *description         = "J2 plasticity without hardening (a test's member).";
    static constexpr MaterialOwner owner               = MaterialOwner::test;
    static constexpr bool          plastic             = true;
    static constexpr bool          in_standard_kernels = false;

    // Also evaluated with Real = Dual (the FEM stage's tangent).
    template <typename Real>
    MPM_HOST_DEVICE static ReturnResult<Real> return_mapping(const LinearElasticParameters<Real> &elastic,
                                                             const Parameters<Real> &p, SymTensor<Real> &trial,
                                                             const Real)
    {
      using std::sqrt;
      const Real mean = (trial[0] + trial[1] + trial[2]) / Real(3);
      Real       j2   = Real(0);
      for (int c = 0; c < n_voigt; ++c)
        {
          const Real s = c < 3 ? trial[c] - mean : trial[c];
          j2 += (c < 3 ? Real(0.5) : Real(1)) * s * s;
        }
      const Real q = sqrt(Real(3) * j2);
      if (!(q > p.yield_stress))
        return elastic_return<Real>();
      const Real scale = p.yield_stress / q;
      for (int c = 0; c < n_voigt; ++c)
        trial[c] = c < 3 ? mean + (trial[c] - mean) * scale : trial[c] * scale;
      ReturnResult<Real> r;
      r.mode             = ReturnMode::shear;
      r.multiplier[0]    = (q - p.yield_stress) / (Real(3) * elastic.shear_modulus());
      r.multiplier[1]    = Real(0);
      r.d_plastic_strain = r.multiplier[0];
      return r;
    }

    static ReturnResult<double> tangent(const LinearElasticParameters<double> &elastic, const Parameters<double> &p,
                                        const double, SymTensor<double> &stress, Tangent C)
    {
      using D6 = Dual<n_voigt>;
      const Parameters<D6> pd{D6(p.yield_stress)};
      return voigt_tangent(elastic, stress, C, [&](const LinearElasticParameters<D6> &e, SymTensor<D6> &s) {
        return return_mapping(e, pd, s, D6(0.0));
      });
    }

    template <typename Real>
    MPM_HOST_DEVICE static SofteningStrength<Real> *strength(Parameters<Real> &)
    {
      return nullptr;
    }

    template <typename Real>
    MPM_HOST_DEVICE static Parameters<Real> reduced(Parameters<Real> p, const Real factor)
    {
      p.yield_stress = p.yield_stress / factor;
      return p;
    }

    template <typename To, typename From>
    static Parameters<To> converted(const Parameters<From> &p)
    {
      return {static_cast<To>(p.yield_stress)};
    }

    static void declare(MaterialEntries &entries)
    {
      declare_elastic_entries(entries);
      entries.real("Yield stress", "1e30", 0, MaterialEntries::unbounded, "sigma_y = sqrt(3 J2) at yield (Pa).");
    }

    static Parameters<double> parse(const MaterialEntryValues &values)
    {
      Parameters<double> p;
      p.yield_stress = values.real("Yield stress");
      values.require(p.yield_stress > 0, "Yield stress", "must be > 0, got " + values.as_written("Yield stress") + ".");
      return p;
    }
  };
} // namespace mpm
