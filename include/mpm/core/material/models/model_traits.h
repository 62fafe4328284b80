// What every member of the material family (material_family.h) declares, and the pieces two
// members share. A member is a struct of static functions and constants:
//   template <typename Real> using Parameters = ...;   its own parameters (plain data)
//   name, description                                   its prm name (Model = name) and one line
//   owner                                               always, or test (registered only by tests)
//   plastic                                             it has a return mapping
//   in_standard_kernels                                 the device's standard kernels compile it
//                                                       (false: only DevicePhysics::all; step.h)
//   return_mapping(elastic, p, trial, eps_p)            MPM_HOST_DEVICE; trial in, admissible out
//   tangent(elastic, p, eps_p, stress, C)               the FEM stage's consistent tangent (host)
//   strength(p)                                         its c-phi strength, or nullptr (random
//                                                       fields of c or phi)
//   reduced(p, F), converted<To>(p)                     strength reduction; another float type
//   declare(entries), parse(values)                     its prm section (material_entries.h)
#pragma once

#include <mpm/core/material/consistent_tangent.h>
#include <mpm/core/material/material_entries.h>

namespace mpm
{
  enum class MaterialOwner : int
  {
    always, // in every program's prm
    test    // a test's member: registered only where register_test_materials() is called
  };

  // The parameters of a member that has none besides the elastic part.
  template <typename Real>
  struct NoModelParameters
  {};
} // namespace mpm
