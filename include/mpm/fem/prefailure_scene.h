// What the pre-failure FEM stage is given of a scene: its own settings (subsection Pre-failure
// analysis), the soil's materials, gravity, where to write, and the body it meshes where
// Mesh = prm bodies. A program that runs the FEM stage fills it from its own description of the
// scene (the executable: run/scene.h's prefailure_scene from the parameter file).
#pragma once

#include <mpm/core/material/material.h>
#include <mpm/fem/prefailure_parameters.h>

#include <array>
#include <map>
#include <string>
#include <utility>
#include <vector>

namespace mpm::fem
{
  // A body the FEM stage can mesh (Mesh = prm bodies): a box, or a polygon in (horizontal,
  // vertical) coordinates, extruded along y in 3D between lower[1] and upper[1].
  struct MeshedBody
  {
    std::string                        shape; // box | polygon (any other is refused with a message)
    std::vector<double>                lower, upper;
    std::vector<std::array<double, 2>> polygon;
    unsigned int                       material = 0; // index into material_names
    double                             density  = 0; // kg/m^3
  };

  struct PrefailureScene
  {
    PrefailureParameters settings;
    // The scene's materials (Materials/Names order) and their constitutive parameters.
    std::vector<std::string>                material_names;
    std::vector<MaterialParameters<double>> materials;
    // Mesh = mesh file: material_id -> (index into materials, density), Initial state/Materials.
    std::map<unsigned int, std::pair<unsigned int, double>> mesh_materials;
    // Mesh = prm bodies: the bodies of the scene (the FEM meshes one).
    std::vector<MeshedBody> bodies;
    std::vector<double>     gravity;           // m/s^2, dim components
    double                  default_cell_size = 0; // m: the FEM's where settings.cell_size is 0 (Grid/Cell size)
    std::string             output_directory;
  };
} // namespace mpm::fem
