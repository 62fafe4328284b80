// "linear elastic": Hooke's law in Jaumann rate form (include/mpm/core/material/linear_elastic.h).
#include <mpm/dealii/material_library.h>

#include <deal.II/base/exceptions.h>

namespace mpm
{
  namespace
  {
    void declare(dealii::ParameterHandler &prm)
    {
      using dealii::Patterns::Double;
      prm.declare_entry("Young's modulus", "1e6", Double(0), "Young's modulus E in Pa (> 0).");
      prm.declare_entry("Poisson's ratio", "0.3", Double(-1, 0.5), "Poisson's ratio nu, -1 < nu < 0.5.");
    }

    MaterialParameters<double> parse(dealii::ParameterHandler &prm)
    {
      MaterialParameters<double> m{};
      m.model                  = MaterialModel::linear_elastic;
      m.elastic.youngs_modulus = prm.get_double("Young's modulus");
      m.elastic.poissons_ratio = prm.get_double("Poisson's ratio");
      AssertThrow(m.elastic.youngs_modulus > 0,
                  dealii::ExcMessage("Entry 'Young's modulus' must be > 0, got " +
                                     prm.get("Young's modulus") + "."));
      AssertThrow(m.elastic.poissons_ratio > -1 && m.elastic.poissons_ratio < 0.5,
                  dealii::ExcMessage("Entry 'Poisson's ratio' must lie in (-1, 0.5), got " +
                                     prm.get("Poisson's ratio") + "."));
      return m;
    }
  } // namespace

  MPM_REGISTER_MATERIAL(linear_elastic, "linear elastic",
                        (MaterialPlugin{"Linear elastic, hypoelastic with the Jaumann stress rate.", declare,
                                        parse}));
} // namespace mpm
