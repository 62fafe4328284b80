// Constitutive models by name. The built-in models are the core's material family
// (include/mpm/core/material/material_family.h): each declares its prm section without deal.II
// (material_entries.h), and material_library.cc registers every one owned by `always` under its
// name through the adapters below.
//
// A user's program adds its own model the same way, from its own file, without touching the
// library (examples/custom_material):
//
//   class VonMises : public mpm::UserConstitutiveModel
//   {
//   public:
//     static void declare_parameters(dealii::ParameterHandler &prm);  // its prm entries
//     void parse_parameters(dealii::ParameterHandler &prm);           // reads them, throws on bad ones
//     void update_stress(...) const override;                         // user_model.h
//     std::vector<mpm::StateVariable> state_variables() const override; // optional: its own state
//     mpm::LinearElasticParameters<double> elastic_parameters() const override;
//   };
//   MPM_REGISTER_CONSTITUTIVE_MODEL(VonMises, "von mises", "J2 plasticity, perfectly plastic.");
//
// A prm file then selects it as any built-in one (Material <name>/Model = von mises, entries in
// subsection von mises). Registration runs before main(), so the model is known to every
// ParameterHandler the program declares. User models run on the CPU backend.
#pragma once

#include <mpm/core/material/material.h>
#include <mpm/core/material/material_entries.h>
#include <mpm/core/material/user_model.h>

#include <deal.II/base/parameter_handler.h>

#include <functional>
#include <map>
#include <memory>
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

  // The core's entry interfaces over a ParameterHandler whose subsection is entered.
  class HandlerEntries : public MaterialEntries
  {
  public:
    explicit HandlerEntries(dealii::ParameterHandler &prm);
    void real(const std::string &name, const std::string &default_value, double min, double max,
              const std::string &documentation) override;

  private:
    dealii::ParameterHandler &prm;
  };

  class HandlerEntryValues : public MaterialEntryValues
  {
  public:
    explicit HandlerEntryValues(dealii::ParameterHandler &prm);
    double      real(const std::string &name) const override;
    std::string as_written(const std::string &name) const override;
    // Throws ExcMessage("Entry 'name' what").
    [[noreturn]] void fail(const std::string &name, const std::string &what) const override;

  private:
    dealii::ParameterHandler &prm;
  };

  // Adds the built-in members owned by `test` (material_family.h) to the library; a test calls
  // it before it declares its parameters. Calling it again does nothing.
  void register_test_materials();

  // Adds a model under `name`; a name may be registered once (throws otherwise).
  bool register_material(const std::string &name, const MaterialPlugin &plugin);

  // "a|b|c" of every registered name, for Patterns::Selection.
  std::string material_model_names();

  // The core's description of a user model (tag user_defined, elastic part for the time step).
  // The library keeps `model` alive until the program ends.
  MaterialParameters<double> user_defined_material(std::shared_ptr<const UserConstitutiveModel> model);

  // The plugin of a class Model as sketched above.
  template <class Model>
  MaterialPlugin constitutive_model_plugin(const std::string &description)
  {
    return MaterialPlugin{description,
                          [](dealii::ParameterHandler &prm) { Model::declare_parameters(prm); },
                          [](dealii::ParameterHandler &prm) {
                            auto model = std::make_shared<Model>();
                            model->parse_parameters(prm);
                            return user_defined_material(model);
                          }};
  }
} // namespace mpm

#define MPM_REGISTER_MATERIAL(identifier, name, plugin) \
  static const bool mpm_material_registered_##identifier = ::mpm::register_material(name, plugin)

#define MPM_REGISTER_CONSTITUTIVE_MODEL(classname, name, description) \
  MPM_REGISTER_MATERIAL(classname, name, ::mpm::constitutive_model_plugin<classname>(description))
