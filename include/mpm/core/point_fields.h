// The per-point fields, declared once. The views the step works on, the host and device
// owners of the arrays, every copy between them (upload, sort, migration, gather, float
// conversion), the ParticleHandler's property layout, checkpoints and output follow from
// this list; a new field is one line here (doc/dev/extending.md).
#pragma once

#include <mpm/core/config.h>

#include <cstddef>
#include <cstdint>
#include <type_traits>

namespace mpm
{
  // How many arrays a field has: one; one per axis (a deal.II vector in output); one per
  // Voigt component (output name_xx, name_yy, ...); one per entry of a dim x dim tensor,
  // row-major (name_xx, name_xy, ...).
  enum class FieldShape
  {
    scalar,
    vector,
    voigt,
    tensor
  };

  // Where a field lives: in the core's arrays (the step, the GPU) and as properties of the
  // ParticleHandler's particles; in the core only (the position: the handler keeps it as the
  // particle's location); or in the handler only (a label the core never reads).
  enum class FieldPlace
  {
    core_and_handler,
    core,
    handler
  };

  // Who asks for a field: every run, or only a run (or a test) that names it in its
  // PointFieldSet; arrays of fields nobody asks for are not allocated, and their pointers in
  // the views are null.
  enum class FieldOwner
  {
    always,
    test
  };

  // X(member, output name, shape, type: real|integer, initial value: zero|identity, place,
  //   owner, written by the step: whether the handler takes it back after steps)
  // The order is the ParticleHandler's property order (and so output's column order).
#define MPM_POINT_FIELDS(X)                                                                                           \
  X(position, "position", vector, real, zero, core, always, true)                                                    \
  X(mass, "mass", scalar, real, zero, core_and_handler, always, false)                                                \
  X(volume, "volume", scalar, real, zero, core_and_handler, always, true)                                             \
  X(initial_volume, "initial_volume", scalar, real, zero, core_and_handler, always, false)                            \
  X(velocity, "velocity", vector, real, zero, core_and_handler, always, true)                                         \
  X(stress, "stress", voigt, real, zero, core_and_handler, always, true)                                              \
  X(strain, "strain", voigt, real, zero, core_and_handler, always, true) /* accumulated small strain */               \
  X(deformation_gradient, "F", tensor, real, identity, core_and_handler, always, true) /* 2D: F_zz = 1 */             \
  X(domain_half_length, "domain_half_length", vector, real, zero, core_and_handler, always, true) /* GIMP, current */ \
  X(initial_domain_half_length, "initial_domain_half_length", vector, real, zero, core_and_handler, always, false)     \
  X(plastic_strain, "plastic_strain", scalar, real, zero, core_and_handler, always, true) /* equivalent */            \
  X(material, "material_id", scalar, integer, zero, core_and_handler, always, false) /* < 0: left the grid */         \
  X(initial_position, "initial_position", vector, real, zero, handler, always, false)                                 \
  X(material_field, "material_field", scalar, real, zero, core_and_handler, always, false) /* random field */            \
  X(test_tag, "test_tag", scalar, real, zero, core_and_handler, test, true) /* tests/dealii/test_point_field.cc */

  // One value per field of the list, in its order.
  enum class PointField : int
  {
#define MPM_POINT_FIELD_ENUM(member, ...) member,
    MPM_POINT_FIELDS(MPM_POINT_FIELD_ENUM)
#undef MPM_POINT_FIELD_ENUM
  };

  constexpr int n_point_fields = 0
#define MPM_POINT_FIELD_COUNT(...) +1
    MPM_POINT_FIELDS(MPM_POINT_FIELD_COUNT)
#undef MPM_POINT_FIELD_COUNT
    ;

  // A field's declaration as data, for the layers that build names and layouts from it.
  struct PointFieldInfo
  {
    const char *member;
    const char *output_name;
    FieldShape  shape;
    bool        integer;
    bool        identity; // initial value: the identity tensor, else zero
    FieldPlace  place;
    FieldOwner  owner;
    bool        written_by_step;
  };

#define MPM_POINT_FIELD_INFO(member, output, shape, kind, initial, place, owner, written)                        \
  PointFieldInfo{#member,                                                                                          \
                 output,                                                                                           \
                 FieldShape::shape,                                                                                \
                 MPM_POINT_FIELD_IS_INTEGER_##kind,                                                                \
                 MPM_POINT_FIELD_IS_IDENTITY_##initial,                                                            \
                 FieldPlace::place,                                                                                \
                 FieldOwner::owner,                                                                                \
                 written},
#define MPM_POINT_FIELD_IS_INTEGER_real false
#define MPM_POINT_FIELD_IS_INTEGER_integer true
#define MPM_POINT_FIELD_IS_IDENTITY_zero false
#define MPM_POINT_FIELD_IS_IDENTITY_identity true
  inline constexpr PointFieldInfo point_field_info[] = {MPM_POINT_FIELDS(MPM_POINT_FIELD_INFO)};
#undef MPM_POINT_FIELD_INFO
#undef MPM_POINT_FIELD_IS_IDENTITY_zero
#undef MPM_POINT_FIELD_IS_IDENTITY_identity

  constexpr const PointFieldInfo &info(const PointField f) { return point_field_info[static_cast<int>(f)]; }

  // Arrays of a field of this shape.
  template <int dim>
  constexpr int field_arrays(const FieldShape shape)
  {
    return shape == FieldShape::scalar ? 1 : shape == FieldShape::vector ? dim : shape == FieldShape::voigt ? n_voigt : dim * dim;
  }

  // The fields a run's points carry: those owned by `always`, and those asked for.
  class PointFieldSet
  {
  public:
    constexpr PointFieldSet()
    {
      for (int f = 0; f < n_point_fields; ++f)
        if (point_field_info[f].owner == FieldOwner::always)
          bits |= std::uint64_t(1) << f;
    }
    constexpr bool has(const PointField f) const { return (bits >> static_cast<int>(f)) & 1; }
    constexpr void insert(const PointField f) { bits |= std::uint64_t(1) << static_cast<int>(f); }
    constexpr bool operator==(const PointFieldSet &o) const { return bits == o.bits; }
    constexpr bool operator!=(const PointFieldSet &o) const { return bits != o.bits; }

  private:
    std::uint64_t bits = 0;
    static_assert(n_point_fields <= 64, "PointFieldSet holds 64 fields");
  };

  // The member type of a field in an owner whose one array is `Array`: Array itself for a
  // scalar, else Array[n] (T *velocity[dim] in a view, std::vector<T> stress[n_voigt] on the host).
  template <typename Array, FieldShape shape, int dim>
  struct FieldMember
  {
    using type = Array[field_arrays<dim>(shape)];
  };
  template <typename Array, int dim>
  struct FieldMember<Array, FieldShape::scalar, dim>
  {
    using type = Array;
  };

  // The element type named in the list, with the floating-point type of the owner.
  template <typename Real, bool integer>
  struct FieldScalar
  {
    using type = Real;
  };
  template <typename Real>
  struct FieldScalar<Real, true>
  {
    using type = int;
  };
} // namespace mpm

// Inside an owner of point arrays (a template with `dim` and `Real`, and an alias template
// FieldArray<T>: T * in a view, std::vector<T> on the host, DeviceArray<T> on the GPU): one
// member per core field, a FieldArray or, for several arrays, a C array of them, empty (null)
// until the owner allocates it.
#define MPM_POINT_CORE_MEMBER_core(member, shape, kind)                                                              \
  typename ::mpm::FieldMember<FieldArray<typename ::mpm::FieldScalar<Real, MPM_POINT_FIELD_IS_INTEGER_##kind>::type>, \
                              ::mpm::FieldShape::shape, dim>::type member = {};
#define MPM_POINT_CORE_MEMBER_core_and_handler(member, shape, kind) MPM_POINT_CORE_MEMBER_core(member, shape, kind)
#define MPM_POINT_CORE_MEMBER_handler(member, shape, kind)
#define MPM_POINT_CORE_MEMBER(member, output, shape, kind, initial, place, owner, written)                          \
  MPM_POINT_CORE_MEMBER_##place(member, shape, kind)
#define MPM_POINT_CORE_MEMBERS MPM_POINT_FIELDS(MPM_POINT_CORE_MEMBER)

namespace mpm
{
  // f(field, a.member[, b.member]) for each core field of the list, in its order: the member
  // whole (one array, or a C array of them).
  template <typename A, typename F>
  void for_each_core_field(A &a, F &&f)
  {
#define MPM_VISIT_core(member) f(PointField::member, a.member);
#define MPM_VISIT_core_and_handler(member) MPM_VISIT_core(member)
#define MPM_VISIT_handler(member)
#define MPM_VISIT(member, output, shape, kind, initial, place, owner, written) MPM_VISIT_##place(member)
    MPM_POINT_FIELDS(MPM_VISIT)
#undef MPM_VISIT_core
  }

  template <typename A, typename B, typename F>
  void for_each_core_field(A &a, B &b, F &&f)
  {
#define MPM_VISIT_core(member) f(PointField::member, a.member, b.member);
    MPM_POINT_FIELDS(MPM_VISIT)
#undef MPM_VISIT_core
#undef MPM_VISIT_core_and_handler
#undef MPM_VISIT_handler
#undef MPM_VISIT
  }

  // g(array) for each array of a member (one, or each of a C array).
  template <typename Member, typename G>
  void for_each_array_of(Member &member, G &&g)
  {
    if constexpr (std::is_array_v<Member>)
      for (auto &array : member)
        g(array);
    else
      g(member);
  }
  template <typename MemberA, typename MemberB, typename G>
  void for_each_array_of(MemberA &a, MemberB &b, G &&g)
  {
    if constexpr (std::is_array_v<MemberA>)
      {
        static_assert(std::extent_v<MemberA> == std::extent_v<MemberB>, "matching members");
        for (std::size_t c = 0; c < std::extent_v<MemberA>; ++c)
          g(a[c], b[c]);
      }
    else
      g(a, b);
  }
} // namespace mpm
