#include <mpm/dealii/material_library.h>

#include <deal.II/base/exceptions.h>

#include <cstdlib>
#include <mutex>
#include <vector>

namespace mpm
{
  std::map<std::string, MaterialPlugin> &material_library()
  {
    static std::map<std::string, MaterialPlugin> library;
    return library;
  }

  HandlerEntries::HandlerEntries(dealii::ParameterHandler &prm)
    : prm(prm)
  {}

  void HandlerEntries::real(const std::string &name, const std::string &default_value, const double min,
                            const double max, const std::string &documentation)
  {
    prm.declare_entry(name, default_value, dealii::Patterns::Double(min, max), documentation);
  }

  HandlerEntryValues::HandlerEntryValues(dealii::ParameterHandler &prm)
    : prm(prm)
  {}

  double HandlerEntryValues::real(const std::string &name) const
  {
    return prm.get_double(name);
  }

  std::string HandlerEntryValues::as_written(const std::string &name) const
  {
    return prm.get(name);
  }

  void HandlerEntryValues::fail(const std::string &name, const std::string &what) const
  {
    AssertThrow(false, dealii::ExcMessage("Entry '" + name + "' " + what));
    std::abort(); // not reached: AssertThrow throws
  }

  namespace
  {
    // The plugin of built-in member Member: its section, its parameters with the elastic part.
    template <typename Member>
    MaterialPlugin built_in_plugin()
    {
      return MaterialPlugin{Member::description,
                            [](dealii::ParameterHandler &prm) {
                              HandlerEntries entries(prm);
                              Member::declare(entries);
                            },
                            [](dealii::ParameterHandler &prm) {
                              const HandlerEntryValues   values(prm);
                              MaterialParameters<double> m{};
                              m.model                          = tag_of<Member>();
                              m.elastic                        = parse_elastic_entries(values);
                              parameters_of<Member>(m)         = Member::parse(values);
                              return m;
                            }};
    }

    void register_built_in(const MaterialOwner owner)
    {
      for_each_built_in_model([&](auto member) {
        using Member = decltype(member);
        if (Member::owner == owner)
          register_material(Member::name, built_in_plugin<Member>());
      });
    }

    [[maybe_unused]] const bool built_in_registered = (register_built_in(MaterialOwner::always), true);
  } // namespace

  void register_test_materials()
  {
    static const bool registered = (register_built_in(MaterialOwner::test), true);
    (void)registered;
  }

  bool register_material(const std::string &name, const MaterialPlugin &plugin)
  {
    AssertThrow(!name.empty() && name.find_first_of("|,") == std::string::npos,
                dealii::ExcMessage("A constitutive model's name must be non-empty and contain neither '|' nor ','; "
                                   "got '" + name + "'."));
    AssertThrow(material_library().count(name) == 0,
                dealii::ExcMessage("The constitutive model name '" + name + "' is registered twice."));
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

  MaterialParameters<double> user_defined_material(std::shared_ptr<const UserConstitutiveModel> model)
  {
    AssertThrow(model != nullptr, dealii::ExcMessage("user_defined_material: no model given."));
    // The parsed models live as long as the program: MaterialParameters are plain data copied
    // into engines that outlive any one Parameters object.
    static std::mutex                                                 mutex;
    static std::vector<std::shared_ptr<const UserConstitutiveModel>> keep_alive;
    {
      std::lock_guard<std::mutex> lock(mutex);
      keep_alive.push_back(model);
    }
    MaterialParameters<double> m{};
    m.model      = MaterialModel::user_defined;
    m.elastic    = model->elastic_parameters();
    m.user_model = model.get();
    const LinearElasticParameters<double> &e = m.elastic;
    AssertThrow(e.youngs_modulus > 0 && e.poissons_ratio > -1 && e.poissons_ratio < 0.5,
                dealii::ExcMessage("The model's elastic_parameters() must give E > 0 and -1 < nu < 0.5."));
    return m;
  }
} // namespace mpm
