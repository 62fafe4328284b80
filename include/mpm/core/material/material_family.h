// The built-in constitutive models, listed once: X(identifier, member). A member is one header
// (models/, model_traits.h says what it declares); listing it here gives it a tag in
// MaterialModel, its parameters in MaterialParameters, a case in every dispatch (the CPU and
// GPU step, the FEM stage's tangent, strength reduction, float conversion) and, in the deal.II
// layer, its prm section under its name. A member owned by `test` is in the prm only where a
// test calls register_test_materials().
#pragma once

#include <mpm/core/material/models/drucker_prager_model.h>
#include <mpm/core/material/models/linear_elastic_model.h>
#include <mpm/core/material/models/mohr_coulomb_model.h>
#include <mpm/core/material/models/test_von_mises_model.h>

#include <string>
#include <vector>

#define MPM_BUILT_IN_MATERIALS(X)          \
  X(linear_elastic, LinearElasticModel)    \
  X(drucker_prager, DruckerPragerModel)    \
  X(mohr_coulomb, MohrCoulombModel)        \
  X(test_von_mises, TestVonMisesModel)

namespace mpm
{
  enum class MaterialModel : int
  {
#define MPM_MATERIAL_TAG(identifier, Member) identifier,
    MPM_BUILT_IN_MATERIALS(MPM_MATERIAL_TAG)
#undef MPM_MATERIAL_TAG
    user_defined // UserConstitutiveModel, a virtual call per point (CPU only)
  };

  // The tag of built-in member Member.
  template <typename Member>
  MPM_HOST_DEVICE constexpr MaterialModel tag_of();
#define MPM_MATERIAL_TAG_OF(identifier, Member)                  \
  template <>                                                    \
  MPM_HOST_DEVICE constexpr MaterialModel tag_of<Member>()       \
  {                                                              \
    return MaterialModel::identifier;                            \
  }
  MPM_BUILT_IN_MATERIALS(MPM_MATERIAL_TAG_OF)
#undef MPM_MATERIAL_TAG_OF

  // f(Member{}) for the built-in member of tag `model`; nothing for user_defined.
  template <typename F>
  MPM_HOST_DEVICE inline void with_built_in_model(const MaterialModel model, F &&f)
  {
    switch (model)
      {
#define MPM_MATERIAL_CASE(identifier, Member) \
  case MaterialModel::identifier:             \
    f(Member{});                              \
    return;
        MPM_BUILT_IN_MATERIALS(MPM_MATERIAL_CASE)
#undef MPM_MATERIAL_CASE
        default:
          return;
      }
  }

  // f(Member{}) for every member, in the list's order.
  template <typename F>
  inline void for_each_built_in_model(F &&f)
  {
#define MPM_MATERIAL_VISIT(identifier, Member) f(Member{});
    MPM_BUILT_IN_MATERIALS(MPM_MATERIAL_VISIT)
#undef MPM_MATERIAL_VISIT
  }

  // A property of the member of tag `model`; `otherwise` for user_defined.
  template <typename F>
  MPM_HOST_DEVICE inline bool built_in_model_is(const MaterialModel model, F &&property, const bool otherwise)
  {
    bool result = otherwise;
    with_built_in_model(model, [&](auto member) { result = property(member); });
    return result;
  }

  // Whether member Member has a c-phi strength (SofteningStrength) that random fields of c or
  // phi reach.
  template <typename Member>
  inline bool has_friction_strength()
  {
    typename Member::template Parameters<double> p{};
    return Member::strength(p) != nullptr;
  }

  // The members' prm names that satisfy `property`, "a, b or c".
  template <typename F>
  inline std::string built_in_model_names(F &&property)
  {
    std::vector<std::string> names;
    for_each_built_in_model([&](auto member) {
      if (decltype(member)::owner == MaterialOwner::always && property(member))
        names.emplace_back(decltype(member)::name);
    });
    std::string text;
    for (std::size_t i = 0; i < names.size(); ++i)
      text += (i == 0 ? "" : i + 1 == names.size() ? " or " : ", ") + names[i];
    return text;
  }
} // namespace mpm
