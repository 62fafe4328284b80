// What the FEM stage knows of the soil in the cells of one material_id: the core's
// constitutive parameters (the same return mappings as the MPM step), the density, and which
// prm material it is (the MPM continues with it after the hand-over).
#pragma once

#include <mpm/core/material/material.h>

#include <string>

namespace mpm::fem
{
  struct FemMaterial
  {
    MaterialParameters<double> parameters;
    double                     density      = 0; // kg/m^3
    unsigned int               mpm_material = 0; // index into Materials/Names
    std::string                name;
  };
} // namespace mpm::fem
