// Small scenes shared by the core tests and benchmarks.
#pragma once

#include <mpm/core/backend/cpu_backend.h>
#include <mpm/core/host_storage.h>
#include <mpm/core/material/material.h>
#include <mpm/core/step.h>

#include <algorithm>
#include <random>
#include <vector>

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
  // What a block that slides along x did: its centre of mass moved by `distance`, and it ends
  // with the mean velocity `speed` (momentum over mass along x).
  struct Slide
  {
    double distance;
    double speed;
  };

  // Runs the points on the CPU with GIMP to t_end at CFL 0.5 (c: the elastic wave speed) and
  // reports their slide along x.
  template <int dim>
  Slide slide_along_x(mpm::HostGrid<dim, double> &grid, mpm::HostPoints<dim, double> &p,
                      const std::vector<mpm::MaterialParameters<double>> &materials,
                      const mpm::StepSettings<dim, double> &s, const double c, const double t_end)
  {
    mpm::CpuBackend backend;
    auto            centre = [&]() {
      double mx = 0, m = 0;
      for (int i = 0; i < p.size(); ++i)
        mx += p.mass[i] * p.position[0][i], m += p.mass[i];
      return mx / m;
    };
    const double x0 = centre();
    double       t = 0, max_speed = 0;
    while (t < t_end)
      {
        const double dt = std::min(0.5 * grid.h / (c + max_speed), t_end - t);
        max_speed = mpm::explicit_step<dim, mpm::GimpShape>(backend, grid.view(), p.view(), materials.data(), s, dt)
                      .max_speed;
        t += dt;
      }
    double momentum = 0, mass = 0;
    for (int i = 0; i < p.size(); ++i)
      momentum += p.mass[i] * p.velocity[0][i], mass += p.mass[i];
    return {centre() - x0, momentum / mass};
  }
} // namespace mpm_test
