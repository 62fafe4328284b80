// "mohr coulomb": non-associated Mohr-Coulomb with plane, edge and apex returns in
// principal stress space, cohesion/friction softening (include/mpm/core/material/mohr_coulomb.h).
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
    }

    MaterialParameters<double> parse(dealii::ParameterHandler &prm)
    {
      MaterialParameters<double> m{};
      m.model                 = MaterialModel::mohr_coulomb;
      m.elastic               = parse_elastic_parameters(prm);
      m.mohr_coulomb.strength = parse_strength_parameters(prm);
      return m;
    }
  } // namespace

  MPM_REGISTER_MATERIAL(mohr_coulomb, "mohr coulomb",
                        (MaterialPlugin{"Mohr-Coulomb, non-associated, principal-space return, softening.", declare,
                                        parse}));
} // namespace mpm
