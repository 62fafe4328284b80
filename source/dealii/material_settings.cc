#include <mpm/dealii/material_library.h>
#include <mpm/dealii/material_settings.h>
#include <mpm/dealii/parameter_error.h>
#include <mpm/dealii/prm_reading.h>

#include <deal.II/base/exceptions.h>
#include <deal.II/base/utilities.h>

#include <cmath>
#include <sstream>

namespace mpm
{
  using dealii::ParameterHandler;
  namespace Patterns = dealii::Patterns;
  using namespace prm_reading;

  namespace
  {
    // The built-in models' names for messages (material_family.h).
    const std::string any_built_in_model = built_in_model_names([](auto) { return true; });
    const std::string models_with_strength =
      built_in_model_names([](auto member) { return has_friction_strength<decltype(member)>(); });
  } // namespace

  void MaterialSettings::declare(ParameterHandler &prm, const unsigned int dim,
                                 const std::vector<std::string> &material_names)
  {
    for (const std::string &name : material_names)
      {
        prm.enter_subsection("Material " + name);
        prm.declare_entry("Model", "linear elastic", Patterns::Selection(material_model_names()),
                          "Constitutive model of this material, one of: " + material_model_names() + ".");
        prm.declare_entry("Elastic law", "Jaumann rate", Patterns::Selection("Jaumann rate|Hencky"),
                          "The elastic part of a built-in model at large strain. Jaumann rate: hypoelastic, the "
                          "stress rotated with the spin plus C : d_eps per step. Hencky: hyperelastic in "
                          "logarithmic strain (Kirchhoff stress = C : ln V_e), plasticity multiplicative with the "
                          "model's return mapping in principal logarithmic strains (doc/theory-plasticity.md). The "
                          "two agree at small strain. Both backends; not with models defined outside the "
                          "library.");
        prm.declare_entry("Disconnection volume ratio", "0", Patterns::Double(0),
                          "A point whose volume exceeds this multiple of its initial volume has lost contact "
                          "(a granular material's disconnected phase): it carries no stress and takes no part "
                          "in the pressure averaging, and compacted back below the ratio its stress starts again "
                          "from zero. Keeps points that a thin front has dilated to many times their volume from "
                          "taking a recompression's stress on that whole volume (doc/methods.md, \"Disconnected "
                          "points\"). 0 (the default): never; otherwise a ratio > 1, e.g. 2. The MPM step only "
                          "(not the FEM stage).");
        for (const auto &[model, plugin] : material_library())
          {
            prm.enter_subsection(model);
            plugin.declare_parameters(prm);
            prm.leave_subsection();
          }
        prm.enter_subsection("Random field");
        prm.declare_entry("Parameter", "none", Patterns::Selection("none|cohesion|friction angle|Young's modulus"),
                          "Material parameter that varies in space as a stationary Gaussian random field sampled at "
                          "the points; its mean is the value given in the model's subsection (cohesion and friction "
                          "angle need a plastic model). Cohesion keeps c_res/c, friction angle keeps phi - phi_res.");
        prm.declare_entry("Covariance", "gaussian", Patterns::Selection("gaussian|exponential"),
                          "gaussian: C(r) = s^2 exp(-sum (r_d/L_d)^2); exponential: C(r) = s^2 exp(-|r/L|).");
        prm.declare_entry("Correlation lengths", ones(dim), point_pattern(dim),
                          "Correlation length L_d along each axis (m, > 0).");
        prm.declare_entry("Standard deviation", "0", Patterns::Double(0),
                          "Standard deviation s, in the parameter's prm unit (Pa, degrees).");
        prm.declare_entry("Seed", "1", Patterns::Integer(0), "Seed of the random numbers (same seed, same field).");
        prm.declare_entry("Maximum clipped fraction", "0.01", Patterns::Double(0, 1),
                          "A Gaussian field can fall below zero: values below 1e-3 of the mean are raised to that "
                          "floor, which shifts the field's mean and distribution. The run is refused when more than "
                          "this fraction of the material's points are raised (a standard deviation large against "
                          "the mean: 1% of a Gaussian lies below mean - 2.33 standard deviations).");
        prm.leave_subsection();
        prm.leave_subsection();
      }
  }

  void MaterialSettings::parse(ParameterHandler &prm)
  {
    prm.enter_subsection("Materials");
    material_names = dealii::Utilities::split_string_list(prm.get("Names"), ',');
    prm.leave_subsection();
    for (unsigned int i = 0; i < material_names.size(); ++i)
      for (unsigned int j = 0; j < i; ++j)
        if (material_names[i] == material_names[j])
          parameter_error("Materials/Names", "the name '" + material_names[i] + "' appears twice.");
    for (const std::string &name : material_names)
      {
        prm.enter_subsection("Material " + name);
        const std::string model = prm.get("Model");
        prm.enter_subsection(model);
        try
          {
            materials.push_back(material_library().at(model).parse_parameters(prm));
          }
        catch (const dealii::ExceptionBase &e)
          {
            // A model's checks say "Entry 'NAME' what": named here by the entry's whole path.
            std::ostringstream info;
            e.print_info(info);
            const std::string what    = dealii::Utilities::trim(info.str());
            const std::string section = "Material " + name + "/" + model;
            const std::size_t closing = what.find("' ", 7);
            if (what.rfind("Entry '", 0) == 0 && closing != std::string::npos)
              parameter_error(section + "/" + what.substr(7, closing - 7), what.substr(closing + 2));
            parameter_error(section, what);
          }
        prm.leave_subsection();
        if (prm.get("Elastic law") == "Hencky")
          {
            if (materials.back().model == MaterialModel::user_defined)
              parameter_error("Material " + name + "/Elastic law", "Hencky needs a built-in model (" + any_built_in_model + "); '" + model + "' is defined outside "
                                                        "the library and gets only strain and spin increments.");
            materials.back().elastic_law = ElasticLaw::hencky;
          }
        {
          const double ratio = prm.get_double("Disconnection volume ratio");
          if (ratio != 0 && !(ratio > 1))
            parameter_error("Material " + name + "/Disconnection volume ratio",
                 "must be 0 (never) or a ratio of volumes greater than 1; got " + prm.get("Disconnection volume ratio") +
                   ".");
          materials.back().disconnection_volume_ratio = ratio;
        }
        if (const UserConstitutiveModel *user = materials.back().user_model)
          {
            const std::vector<StateVariable> variables = user->state_variables();
            if (variables.size() > static_cast<std::size_t>(max_state_variables))
              parameter_error("Material " + name + "/Model", "the model '" + model + "' declares " +
                                                    std::to_string(variables.size()) + " state variables; at most " +
                                                    std::to_string(max_state_variables) + " are allowed.");
            for (const StateVariable &v : variables)
              if (v.name.empty() || v.name.find_first_of(" ,") != std::string::npos)
                parameter_error("Material " + name + "/Model", "the model '" + model + "' declares a state variable named '" +
                                                      v.name + "'; names must be non-empty, without spaces or commas "
                                                      "(they name output fields).");
          }

        // The random field: its mean is the material's own value of the parameter.
        prm.enter_subsection("Random field");
        const std::string  field = prm.get("Parameter");
        const std::string  where = "Material " + name + "/Random field/";
        MaterialParameters<double> &m = materials.back();
        RandomFieldParameters       rf;
        rf.covariance         = prm.get("Covariance") == "exponential" ? Covariance::exponential : Covariance::gaussian;
        rf.correlation_length = get_point(prm, "Correlation lengths", where);
        rf.standard_deviation = prm.get_double("Standard deviation");
        rf.seed               = prm.get_integer("Seed");
        material_field_max_clipped.push_back(prm.get_double("Maximum clipped fraction"));
        for (const double L : rf.correlation_length)
          if (!(L > 0))
            parameter_error(where + "Correlation lengths", "every correlation length must be > 0.");
        const SofteningStrength<double> *strength = nullptr;
        with_built_in_model(m.model, [&](auto member) {
          strength = decltype(member)::strength(parameters_of<decltype(member)>(m));
        });
        if (field != "none" && m.model == MaterialModel::user_defined)
          parameter_error(where + "Parameter", "a random field needs a built-in model (" + any_built_in_model + "); '" + model +
                                                 "' is defined outside the library.");
        if (field == "cohesion" || field == "friction angle")
          {
            if (strength == nullptr)
              parameter_error(where + "Parameter", "'" + field + "' needs a model with c and phi (" + models_with_strength + "), "
                                        "not '" + model + "'.");
            m.field_parameter = field == "cohesion" ? FieldParameter::cohesion : FieldParameter::friction_angle;
            rf.mean           = field == "cohesion" ? strength->cohesion : strength->friction_angle;
            if (field == "friction angle")
              rf.standard_deviation *= M_PI / 180;
          }
        else if (field == "Young's modulus")
          {
            m.field_parameter = FieldParameter::youngs_modulus;
            rf.mean           = m.elastic.youngs_modulus;
          }
        material_fields.push_back(rf);
        prm.leave_subsection();

        prm.leave_subsection();
        material_models.push_back(model);
      }
  }
} // namespace mpm
