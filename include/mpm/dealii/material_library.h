// Constitutive models by name. Each model lives in one file under source/materials/
// that declares its prm entries, parses them into the core's MaterialParameters and
// registers itself with MPM_REGISTER_MATERIAL; nothing else needs to change.
#pragma once

#include <mpm/core/material/material.h>

#include <deal.II/base/parameter_handler.h>

#include <functional>
#include <map>
#include <string>

namespace mpm
{
  struct MaterialPlugin
  {
    std::string description;
    // Declares the entries of the model's own subsection (already entered).
    std::function<void(dealii::ParameterHandler &)> declare_parameters;
    // Reads them; the subsection is entered. Throws naming the entry on bad values.
    std::function<MaterialParameters<double>(dealii::ParameterHandler &)> parse_parameters;
  };

  std::map<std::string, MaterialPlugin> &material_library();

  bool register_material(const std::string &name, const MaterialPlugin &plugin);

  // "a|b|c" of every registered name, for Patterns::Selection.
  std::string material_model_names();
} // namespace mpm

#define MPM_REGISTER_MATERIAL(identifier, name, plugin) \
  static const bool mpm_material_registered_##identifier = ::mpm::register_material(name, plugin)
