// The core's shared entries (material_entries.h) for models written with a ParameterHandler.
#include <mpm/dealii/material_library.h>
#include <mpm/dealii/strength_parameters.h>

namespace mpm
{
  void declare_elastic_parameters(dealii::ParameterHandler &prm)
  {
    HandlerEntries entries(prm);
    declare_elastic_entries(entries);
  }

  LinearElasticParameters<double> parse_elastic_parameters(dealii::ParameterHandler &prm)
  {
    return parse_elastic_entries(HandlerEntryValues(prm));
  }

  void declare_strength_parameters(dealii::ParameterHandler &prm)
  {
    HandlerEntries entries(prm);
    declare_strength_entries(entries);
  }

  SofteningStrength<double> parse_strength_parameters(dealii::ParameterHandler &prm)
  {
    return parse_strength_entries(HandlerEntryValues(prm));
  }
} // namespace mpm
