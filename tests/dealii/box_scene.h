// Parameters of small box scenes for the deal.II-layer tests, set in code (no prm file):
// a cube of free boundaries without gravity and a box body at rest without initial stress.
// Each test adds what it needs on top.
#pragma once

#include <mpm/dealii/parameters.h>

#include <vector>

namespace mpm_test
{
  // Domain [0, extent]^dim, cells of cell_size, free boundaries, no gravity, no body yet.
  template <int dim>
  mpm::Parameters box_domain(const double extent, const double cell_size)
  {
    mpm::Parameters p;
    p.dim       = dim;
    p.lower     = std::vector<double>(dim, 0.0);
    p.upper     = std::vector<double>(dim, extent);
    p.cell_size = cell_size;
    p.boundary.fill(mpm::BoundaryType::free);
    p.gravity      = std::vector<double>(dim, 0.0);
    p.parallel.point_weight = 20;
    return p;
  }

  // A box body [lower, upper]^dim at rest, without initial stress.
  template <int dim>
  mpm::BodyParameters box_body(const double lower, const double upper, const int points_per_direction,
                               const double density)
  {
    mpm::BodyParameters body;
    body.shape                = "box";
    body.lower                = std::vector<double>(dim, lower);
    body.upper                = std::vector<double>(dim, upper);
    body.points_per_direction = points_per_direction;
    body.density              = density;
    body.velocity             = std::vector<double>(dim, 0.0);
    body.initial_stress       = "none";
    body.k0                   = 0.5;
    return body;
  }
} // namespace mpm_test
