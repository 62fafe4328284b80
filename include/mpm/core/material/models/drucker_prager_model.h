// "drucker prager": non-associated Drucker-Prager, inner fit to Mohr-Coulomb, tension cut-off,
// cohesion and friction softening (drucker_prager.h). A member of the material family
// (model_traits.h, material_family.h).
#pragma once

#include <mpm/core/material/drucker_prager.h>
#include <mpm/core/material/models/model_traits.h>

namespace mpm
{
  struct DruckerPragerModel
  {
    template <typename Real>
    using Parameters = DruckerPragerParameters<Real>;

    static constexpr const char   *name = "drucker prager";
    static constexpr const char   *description =
      "Drucker-Prager, non-associated, inner Mohr-Coulomb fit, tension cut-off, softening.";
    static constexpr MaterialOwner owner               = MaterialOwner::always;
    static constexpr bool          plastic             = true;
    static constexpr bool          in_standard_kernels = true;

    template <typename Real>
    MPM_HOST_DEVICE static ReturnResult<Real> return_mapping(const LinearElasticParameters<Real> &elastic,
                                                             const Parameters<Real> &p, SymTensor<Real> &trial,
                                                             const Real eps_p)
    {
      return drucker_prager_return(elastic, drucker_prager_coefficients_at(p, eps_p), trial);
    }

    static ReturnResult<double> tangent(const LinearElasticParameters<double> &elastic, const Parameters<double> &p,
                                        const double eps_p, SymTensor<double> &stress, Tangent C)
    {
      return drucker_prager_tangent(
        elastic, drucker_prager_coefficients(current_strength(p.strength, eps_p), p.tensile_strength), stress, C);
    }

    template <typename Real>
    MPM_HOST_DEVICE static SofteningStrength<Real> *strength(Parameters<Real> &p)
    {
      return &p.strength;
    }

    // The tension cut-off, a strength too, is divided by F.
    template <typename Real>
    MPM_HOST_DEVICE static Parameters<Real> reduced(Parameters<Real> p, const Real factor)
    {
      p.strength         = reduced_strength(p.strength, factor);
      p.tensile_strength = p.tensile_strength / factor;
      return p;
    }

    template <typename To, typename From>
    static Parameters<To> converted(const Parameters<From> &p)
    {
      static_assert(sizeof(Parameters<From>) == 8 * sizeof(From), "a field of DruckerPragerParameters is not copied");
      Parameters<To> r;
      r.strength         = mpm::converted<To>(p.strength);
      r.tensile_strength = static_cast<To>(p.tensile_strength);
      return r;
    }

    static void declare(MaterialEntries &entries)
    {
      declare_elastic_entries(entries);
      declare_strength_entries(entries);
      entries.real("Tensile strength", "1e30", 0, MaterialEntries::unbounded,
                   "Tension cut-off sigma_t (Pa, tension positive); values beyond the cone's apex are capped at "
                   "the apex (the default).");
    }

    static Parameters<double> parse(const MaterialEntryValues &values)
    {
      Parameters<double> p;
      p.strength         = parse_strength_entries(values);
      p.tensile_strength = values.real("Tensile strength");
      return p;
    }
  };
} // namespace mpm
