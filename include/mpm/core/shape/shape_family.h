// The shape functions of the background grid, listed once: X(identifier, Member). A member is
// one struct (shape_traits.h says what it declares); listing it here gives it a tag in
// ShapeFunction, a case in every dispatch (the CPU and GPU step, the device's sort), its
// migration margin, its prm name and documentation, and the checks that follow from its traits
// (GIMP domain update, APIC, one MPI rank). The list's order is the prm's.
#pragma once

#include <mpm/core/config.h>
#include <mpm/core/cpdi.h>
#include <mpm/core/cubic_bspline_gimp.h>
#include <mpm/core/shape/shape_traits.h>
#include <mpm/core/shape/test_wide_linear_shape.h>
#include <mpm/core/shape_functions.h>

#include <string>
#include <vector>

#define MPM_SHAPE_FUNCTIONS(X)                \
  X(linear, LinearShape)                      \
  X(gimp, GimpShape)                          \
  X(bspline2, QuadraticBSplineShape)          \
  X(bspline3, CubicBSplineShape)              \
  X(bspline3_gimp, CubicBSplineGimpShape)     \
  X(cpdi, CpdiShape)                          \
  X(cpdi2q, Cpdi2qShape)                      \
  X(test_wide_linear, TestWideLinearShape)

namespace mpm
{
  enum class ShapeFunction : int
  {
#define MPM_SHAPE_TAG(identifier, Member) identifier,
    MPM_SHAPE_FUNCTIONS(MPM_SHAPE_TAG)
#undef MPM_SHAPE_TAG
  };

  // f(Member{}) for the member of tag `shape` (host code: the dispatch of a step).
  template <typename F>
  inline void with_shape(const ShapeFunction shape, F &&f)
  {
    switch (shape)
      {
#define MPM_SHAPE_CASE(identifier, Member) \
  case ShapeFunction::identifier:          \
    f(Member{});                           \
    return;
        MPM_SHAPE_FUNCTIONS(MPM_SHAPE_CASE)
#undef MPM_SHAPE_CASE
      }
  }

  // f(tag, Member{}) for every member, in the list's order.
  template <typename F>
  inline void for_each_shape(F &&f)
  {
#define MPM_SHAPE_VISIT(identifier, Member) f(ShapeFunction::identifier, Member{});
    MPM_SHAPE_FUNCTIONS(MPM_SHAPE_VISIT)
#undef MPM_SHAPE_VISIT
  }

  // A property of the member of tag `shape`.
  template <typename F>
  inline bool shape_is(const ShapeFunction shape, F &&property)
  {
    bool result = false;
    with_shape(shape, [&](auto member) { result = property(member); });
    return result;
  }

  inline std::string shape_name(const ShapeFunction shape)
  {
    std::string name;
    with_shape(shape, [&](auto member) { name = decltype(member)::name; });
    return name;
  }

  // Whether a member's stencil can reach beyond the ring of nodes around a point's home cell,
  // which is all that a rank holds of its neighbours' part of the grid.
  template <typename Member>
  constexpr bool runs_on_one_rank_only()
  {
    return !Member::tensor_product || Member::safe_distance_outside_home_cell < 0;
  }

  // The device's standard kernels compile the members owned by `always`; a test's member only
  // the DevicePhysics::all variant (as a material's in_standard_kernels).
  inline bool shape_needs_all_physics(const ShapeFunction shape)
  {
    return shape_is(shape, [](auto member) { return decltype(member)::owner != ShapeOwner::always; });
  }

  // The names of the members owned by `always` (and by `test` where with_test_members) for
  // which property(member) holds, in the list's order.
  template <typename F>
  std::vector<std::string> shape_names(const bool with_test_members, F &&property)
  {
    std::vector<std::string> names;
    for_each_shape([&](ShapeFunction, auto member) {
      using Member = decltype(member);
      if ((Member::owner == ShapeOwner::always || with_test_members) && property(member))
        names.emplace_back(Member::name);
    });
    return names;
  }
} // namespace mpm
