// "linear elastic": Hooke's law in Jaumann rate form (linear_elastic.h), or Hencky's where the
// material asks for it. A member of the material family (model_traits.h, material_family.h).
#pragma once

#include <mpm/core/material/models/model_traits.h>

namespace mpm
{
  struct LinearElasticModel
  {
    template <typename Real>
    using Parameters = NoModelParameters<Real>;

    static constexpr const char   *name                = "linear elastic";
    static constexpr const char   *description         = "Linear elastic, hypoelastic with the Jaumann stress rate.";
    static constexpr MaterialOwner owner               = MaterialOwner::always;
    static constexpr bool          plastic             = false;
    static constexpr bool          in_standard_kernels = true;

    template <typename Real>
    MPM_HOST_DEVICE static ReturnResult<Real> return_mapping(const LinearElasticParameters<Real> &,
                                                             const Parameters<Real> &, SymTensor<Real> &, const Real)
    {
      return elastic_return<Real>();
    }

    static ReturnResult<double> tangent(const LinearElasticParameters<double> &elastic, const Parameters<double> &,
                                        const double, SymTensor<double> &, Tangent C)
    {
      elastic_tangent(elastic, C);
      return elastic_return<double>();
    }

    template <typename Real>
    MPM_HOST_DEVICE static SofteningStrength<Real> *strength(Parameters<Real> &)
    {
      return nullptr;
    }

    template <typename Real>
    MPM_HOST_DEVICE static Parameters<Real> reduced(const Parameters<Real> &p, const Real)
    {
      return p;
    }

    template <typename To, typename From>
    static Parameters<To> converted(const Parameters<From> &)
    {
      return {};
    }

    static void declare(MaterialEntries &entries)
    {
      declare_elastic_entries(entries);
    }

    static Parameters<double> parse(const MaterialEntryValues &)
    {
      return {};
    }
  };
} // namespace mpm
