// "mohr coulomb": non-associated Mohr-Coulomb with plane, edge and apex returns in principal
// stress space, cohesion and friction softening (mohr_coulomb.h). A member of the material
// family (model_traits.h, material_family.h).
#pragma once

#include <mpm/core/material/models/model_traits.h>
#include <mpm/core/material/mohr_coulomb.h>

namespace mpm
{
  struct MohrCoulombModel
  {
    template <typename Real>
    using Parameters = MohrCoulombParameters<Real>;

    static constexpr const char   *name        = "mohr coulomb";
    static constexpr const char   *description = "Mohr-Coulomb, non-associated, principal-space return, softening.";
    static constexpr MaterialOwner owner       = MaterialOwner::always;
    static constexpr bool          plastic     = true;
    // Its eigen decomposition (with U's domains) made the standard FP64 kinematics spill: 614 /
    // 1,024 bytes of spill stores / loads at 96 registers against 142 / 272 without it (nvcc,
    // 2026-12-05, doc/performance.md); the standard kernels leave it out.
    static constexpr bool in_standard_kernels = false;

    template <typename Real>
    MPM_HOST_DEVICE static ReturnResult<Real> return_mapping(const LinearElasticParameters<Real> &elastic,
                                                             const Parameters<Real> &p, SymTensor<Real> &trial,
                                                             const Real eps_p)
    {
      return mohr_coulomb_return(elastic, current_strength(p.strength, eps_p), trial);
    }

    static ReturnResult<double> tangent(const LinearElasticParameters<double> &elastic, const Parameters<double> &p,
                                        const double eps_p, SymTensor<double> &stress, Tangent C)
    {
      return mohr_coulomb_tangent(elastic, current_strength(p.strength, eps_p), stress, C);
    }

    template <typename Real>
    MPM_HOST_DEVICE static SofteningStrength<Real> *strength(Parameters<Real> &p)
    {
      return &p.strength;
    }

    template <typename Real>
    MPM_HOST_DEVICE static Parameters<Real> reduced(Parameters<Real> p, const Real factor)
    {
      p.strength = reduced_strength(p.strength, factor);
      return p;
    }

    template <typename To, typename From>
    static Parameters<To> converted(const Parameters<From> &p)
    {
      static_assert(sizeof(Parameters<From>) == 7 * sizeof(From), "a field of MohrCoulombParameters is not copied");
      Parameters<To> r;
      r.strength = mpm::converted<To>(p.strength);
      return r;
    }

    static void declare(MaterialEntries &entries)
    {
      declare_elastic_entries(entries);
      declare_strength_entries(entries);
    }

    static Parameters<double> parse(const MaterialEntryValues &values)
    {
      Parameters<double> p;
      p.strength = parse_strength_entries(values);
      return p;
    }
  };
} // namespace mpm
