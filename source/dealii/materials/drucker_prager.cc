// "drucker prager": non-associated Drucker-Prager, inner fit to Mohr-Coulomb, tension
// cut-off, cohesion/friction softening (include/mpm/core/material/drucker_prager.h).
#include <mpm/dealii/material_library.h>
#include <mpm/dealii/strength_parameters.h>

namespace mpm
{
  namespace
  {
    void declare(dealii::ParameterHandler &prm)
    {
      declare_elastic_parameters(prm);
      declare_strength_parameters(prm);
      prm.declare_entry("Tensile strength", "1e30", dealii::Patterns::Double(0),
                        "Tension cut-off sigma_t (Pa, tension positive); values beyond the cone's apex are capped "
                        "at the apex (the default).");
    }

    MaterialParameters<double> parse(dealii::ParameterHandler &prm)
    {
      MaterialParameters<double> m{};
      m.model                           = MaterialModel::drucker_prager;
      m.elastic                         = parse_elastic_parameters(prm);
      m.drucker_prager.strength         = parse_strength_parameters(prm);
      m.drucker_prager.tensile_strength = prm.get_double("Tensile strength");
      return m;
    }
  } // namespace

  MPM_REGISTER_MATERIAL(drucker_prager, "drucker prager",
                        (MaterialPlugin{"Drucker-Prager, non-associated, inner Mohr-Coulomb fit, tension cut-off, "
                                        "softening.",
                                        declare, parse}));
} // namespace mpm
