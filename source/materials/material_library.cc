#include <mpm/dealii/material_library.h>

namespace mpm
{
  std::map<std::string, MaterialPlugin> &material_library()
  {
    static std::map<std::string, MaterialPlugin> library;
    return library;
  }

  bool register_material(const std::string &name, const MaterialPlugin &plugin)
  {
    material_library()[name] = plugin;
    return true;
  }

  std::string material_model_names()
  {
    std::string names;
    for (const auto &entry : material_library())
      names += (names.empty() ? "" : "|") + entry.first;
    return names;
  }
} // namespace mpm
