// Small scenes shared by the core tests and benchmarks.
#pragma once

#include <mpm/core/host_storage.h>
#include <mpm/core/material/material.h>
#include <mpm/core/step.h>

#include <random>

namespace mpm_test
{
  template <int dim>
  mpm::StepSettings<dim, double> quiet_settings(const mpm::UpdateScheme scheme)
  {
    mpm::StepSettings<dim, double> s;
    s.scheme = scheme;
    for (int d = 0; d < dim; ++d)
      s.gravity[d] = 0;
    s.damping        = 0;
    s.flip_fraction  = 1;
    s.domain_update  = mpm::DomainUpdate::det_F;
    s.mass_tolerance = 1e-14;
    return s;
  }

  inline mpm::MaterialParameters<double> elastic(const double E, const double nu)
  {
    mpm::MaterialParameters<double> m;
    m.model                  = mpm::MaterialModel::linear_elastic;
    m.elastic.youngs_modulus = E;
    m.elastic.poissons_ratio = nu;
    return m;
  }

  // Random points in the middle of a grid, random masses, velocities and stresses.
  template <int dim>
  void random_points(mpm::HostPoints<dim, double> &p, const mpm::HostGrid<dim, double> &g, const int n,
                     std::mt19937 &rng)
  {
    std::uniform_real_distribution<double> u(0.0, 1.0);
    p.resize(n);
    for (int i = 0; i < n; ++i)
      {
        for (int d = 0; d < dim; ++d)
          {
            p.position[d][i] = g.origin[d] + g.h * (2 + u(rng) * (g.n_cells[d] - 4));
            p.velocity[d][i] = u(rng) - 0.5;
            p.domain_half_length[d][i] = p.initial_domain_half_length[d][i] = 0.25 * g.h;
          }
        for (int c = 0; c < mpm::n_voigt; ++c)
          {
            p.stress[c][i] = 100 * (u(rng) - 0.5);
            p.strain[c][i] = 0;
          }
        if (dim == 2)
          p.stress[4][i] = p.stress[5][i] = 0; // plane strain: no out-of-plane shear
        p.mass[i]   = 0.5 + u(rng);
        p.volume[i] = p.initial_volume[i] = 0.01 + 0.01 * u(rng);
        p.plastic_strain[i]               = 0;
        p.material[i]                     = 0;
      }
  }
} // namespace mpm_test
