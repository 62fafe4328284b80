// Material points/Body i: the bodies the points fill at the start (box, polygon, cylinder), their
// density, velocity, material and initial stress.
#pragma once

#include <deal.II/base/parameter_handler.h>

#include <array>
#include <string>
#include <vector>

namespace mpm
{
  struct BodyParameters
  {
    std::string                        shape; // box | polygon | cylinder
    std::vector<double>                lower, upper;
    std::vector<std::array<double, 2>> polygon; // (horizontal, vertical) pairs
    std::array<double, 2>              axis{};  // cylinder: (x, y) of its vertical axis
    double                             radius = 0;
    unsigned int                       points_per_direction;
    double                             density;
    std::vector<double>                velocity;
    std::string                        material;
    std::string                        initial_stress; // none | geostatic
    double                             k0;
  };

  struct BodySettings
  {
    std::vector<BodyParameters> bodies;
    std::vector<unsigned int>   body_material; // index into the materials
    // The bodies' bounding box (Solver/Method = auto measures the resolution across it).
    std::vector<double> bodies_lo, bodies_hi;

    // The subsections Body 1 .. n_bodies of Material points (entered here; Number of bodies is
    // the scene's layout, parameters.cc).
    static void declare(dealii::ParameterHandler &prm, unsigned int dim, unsigned int n_bodies,
                        const std::vector<std::string> &material_names);
    // Checks each body against the materials' names and the grid's box [lower, upper].
    void parse(dealii::ParameterHandler &prm, unsigned int dim, unsigned int n_bodies,
               const std::vector<std::string> &material_names, const std::vector<double> &lower,
               const std::vector<double> &upper);
  };
} // namespace mpm
