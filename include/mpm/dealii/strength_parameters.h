// prm entries shared by the plastic models, for a model written with a ParameterHandler (a
// user model, material_library.h): the core's material_entries.h over the handler. Angles are
// read in degrees and handed to the core in radians.
#pragma once

#include <mpm/core/material/softening.h>
#include <mpm/core/material/linear_elastic.h>

#include <deal.II/base/parameter_handler.h>

namespace mpm
{
  void declare_elastic_parameters(dealii::ParameterHandler &prm);
  LinearElasticParameters<double> parse_elastic_parameters(dealii::ParameterHandler &prm);

  void declare_strength_parameters(dealii::ParameterHandler &prm);
  // Checks c_res <= c, psi <= phi and the like; throws naming the entry.
  SofteningStrength<double> parse_strength_parameters(dealii::ParameterHandler &prm);
} // namespace mpm
