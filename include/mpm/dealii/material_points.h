// Material points in deal.II's ParticleHandler: the property layout (declared once,
// by name, so that output shows every property under its own name), generation
// from the prm bodies, and the copies between the handler and the core's arrays.
#pragma once

#include <mpm/core/host_storage.h>
#include <mpm/dealii/background_grid.h>
#include <mpm/dealii/parameters.h>

#include <deal.II/numerics/data_component_interpretation.h>
#include <deal.II/particles/particle_handler.h>

#include <string>
#include <vector>

namespace mpm
{
  // Offsets of each property in a particle's property array.
  template <int dim>
  struct PropertyLayout
  {
    static constexpr unsigned int mass                 = 0;
    static constexpr unsigned int volume               = 1;
    static constexpr unsigned int initial_volume       = 2;
    static constexpr unsigned int velocity             = 3;
    static constexpr unsigned int stress               = velocity + dim;
    static constexpr unsigned int strain               = stress + n_voigt;
    static constexpr unsigned int deformation_gradient = strain + n_voigt;
    static constexpr unsigned int domain_half_length   = deformation_gradient + dim * dim;
    static constexpr unsigned int initial_domain_half_length = domain_half_length + dim;
    static constexpr unsigned int plastic_strain       = initial_domain_half_length + dim;
    static constexpr unsigned int material             = plastic_strain + 1;
    static constexpr unsigned int initial_position     = material + 1;
    static constexpr unsigned int n_properties         = initial_position + dim;

    static std::vector<std::string> names();
    static std::vector<dealii::DataComponentInterpretation::DataComponentInterpretation> interpretations();
  };

  template <int dim>
  class MaterialPoints
  {
  public:
    MaterialPoints(BackgroundGrid<dim> &grid, const Parameters &parameters);

    // Fills the handler with the points of every body inside this rank's cells.
    void generate(const Parameters &parameters);

    // Handler -> core arrays (after generation and after every re-sort).
    void copy_to(HostPoints<dim, double> &points) const;

    // Core arrays -> handler: positions and properties; points the core marked as
    // having left the grid are removed. Then the handler re-sorts points into cells
    // (and ranks). Returns the number of points removed on this rank.
    unsigned int copy_from(const HostPoints<dim, double> &points);

    dealii::Particles::ParticleHandler<dim> handler;
    dealii::types::particle_index           n_generated = 0;

  private:
    BackgroundGrid<dim> &grid;
  };
} // namespace mpm
