// "linear elastic": Hooke's law in Jaumann rate form (include/mpm/core/material/linear_elastic.h).
#include <mpm/dealii/material_library.h>
#include <mpm/dealii/strength_parameters.h>

namespace mpm
{
  namespace
  {
    void declare(dealii::ParameterHandler &prm)
    {
      declare_elastic_parameters(prm);
    }

    MaterialParameters<double> parse(dealii::ParameterHandler &prm)
    {
      MaterialParameters<double> m{};
      m.model   = MaterialModel::linear_elastic;
      m.elastic = parse_elastic_parameters(prm);
      return m;
    }
  } // namespace

  MPM_REGISTER_MATERIAL(linear_elastic, "linear elastic",
                        (MaterialPlugin{"Linear elastic, hypoelastic with the Jaumann stress rate.", declare,
                                        parse}));
} // namespace mpm
