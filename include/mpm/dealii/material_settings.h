// Materials and Material <name>: each material's name, constitutive model (material_library.h)
// with its own subsection, elastic law, disconnection and random field.
#pragma once

#include <mpm/core/material/material.h>
#include <mpm/fields/gaussian_random_field.h>

#include <deal.II/base/parameter_handler.h>

#include <string>
#include <vector>

namespace mpm
{
  struct MaterialSettings
  {
    // Materials, in the order of their names; bodies refer to them by index.
    std::vector<std::string>                material_names;
    std::vector<std::string>                material_models;
    std::vector<MaterialParameters<double>> materials;
    // Random field of the parameter named by materials[m].field_parameter (core units:
    // Pa, rad), mean = the material's own value.
    std::vector<RandomFieldParameters> material_fields;
    // Per material: the largest fraction of its points whose field value may be raised to
    // the floor (1e-3 of the mean) before the run is refused (Random field/Maximum clipped fraction).
    std::vector<double> material_field_max_clipped;

    // The subsections Material <name> of the given names (Materials/Names is the scene's layout,
    // parameters.cc).
    static void declare(dealii::ParameterHandler &prm, unsigned int dim, const std::vector<std::string> &material_names);
    // Reads Materials/Names and every Material <name>.
    void parse(dealii::ParameterHandler &prm);
  };
} // namespace mpm
