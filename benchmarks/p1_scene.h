// Scene P1 of ../shared/BENCHMARKS.md (the 3D slump as ep2-3De's performance test sets it
// up), elastic phase, generated without deal.II: used by the benchmark and the GPU tests.
//
// Geometry as ep2-3De's setting_Exp2a (mpSetup.m / meSetup.m): h = 64.1584/80 m in every
// direction; points on a regular 2x2x2 sub-lattice per cell at x in [h/4, 64.1584],
// z in [h/4, 12.8 - h/4], y in [h/4, L_y], kept where z < 40.1 - 1.25 x (slope) or
// z < 1.92 m (base layer): 2506 points per y-slice, so 100,240 points for L_y = 20 h.
// The grid reaches 2 cells past the walls (x = 0 and 64.1584, y = 0 and L_y) and the
// base (z = 0), and 20 cells up from z = -2h; free-slip: the normal velocity component is
// prescribed zero on the nodes on or beyond each wall and the base.
// Material: rho = 2700, E = 1 MPa, nu = 0.3; either linear elastic (Jaumann) or, as
// ep2-3De runs it, Drucker-Prager with plasticity on from the start: c = 20 kPa (c_res =
// 4 kPa, softening modulus 60 kPa x h), phi = 20 deg (7 deg in the weak layer z < 3.84 m,
// material 1), psi = 0, tension cut-off at the apex; or Mohr-Coulomb with the same strengths
// (for timing the kernels that hold it). Gravity ramped linearly over 8/1.5 s,
// local damping 0.1, CFL 0.5, 8 s.
#pragma once

#include <mpm/core/host_storage.h>
#include <mpm/core/material/material.h>
#include <mpm/core/step.h>

#include <cmath>
#include <vector>

namespace mpm_bench
{
  struct P1
  {
    static constexpr double length   = 64.1584;
    static constexpr double h        = length / 80;
    static constexpr double height   = 12.8;
    static constexpr double base     = 0.15 * height; // 1.92 m
    static constexpr double slope_z0 = 1.25 * length / 2; // slope plane z = slope_z0 - 1.25 x
    static constexpr double rho      = 2700;
    static constexpr double youngs   = 1e6;
    static constexpr double poisson  = 0.3;
    static constexpr double gravity  = 9.81;
    static constexpr double t_ramp   = 8.0 / 1.5;
    static constexpr double t_end    = 8.0;
    static constexpr double damping  = 0.1;
    static constexpr double cfl      = 0.5;
    static constexpr int    ghost    = 2;  // cells of grid beyond each wall
    static constexpr double weak_layer = 3.84; // Drucker-Prager: phi = 7 deg below this z
    static constexpr int    cells_z  = 20; // from z = -2h
  };

  // The (x, z) sub-lattice sites of one y-slice, in ep2-3De's selection.
  inline void p1_slice(std::vector<double> &xs, std::vector<double> &zs)
  {
    xs.clear();
    zs.clear();
    const double dx = P1::h / 2;
    for (int k = 0;; ++k)
      {
        const double z = (k + 0.5) * dx;
        if (z > P1::height - 0.5 * dx + 1e-9)
          break;
        for (int i = 0;; ++i)
          {
            const double x = (i + 0.5) * dx;
            if (x > P1::length + 1e-9)
              break;
            if (z < P1::slope_z0 - 1.25 * x || z < P1::base)
              {
                xs.push_back(x);
                zs.push_back(z);
              }
          }
      }
  }

  // Scene P1 with n_cells_y cells across (L_y = n_cells_y h): 20, 160, 640, 2560 give
  // 100,240 / 801,920 / 3,207,680 / 12,830,720 points.
  template <typename Real>
  void make_p1(const int n_cells_y, mpm::HostGrid<3, Real> &grid, mpm::HostPoints<3, Real> &points,
               std::vector<mpm::MaterialParameters<Real>> &materials, const bool drucker_prager = false,
               const bool mohr_coulomb = false)
  {
    using namespace mpm;
    const double h        = P1::h;
    const int    g        = P1::ghost;
    const int    cells_x  = 80 + 2 * g;
    const Real   lower[3] = {Real(-g * h), Real(-g * h), Real(-g * h)};
    const int    cells[3] = {cells_x, n_cells_y + 2 * g, P1::cells_z};
    grid.make_dense(lower, Real(h), cells);
    for (long n = 0; n < long(grid.lattice_to_node.size()); ++n)
      {
        int idx[3];
        grid.lattice_coordinates(n, idx);
        std::uint8_t mask = 0;
        if (idx[0] <= g || idx[0] >= 80 + g)
          mask |= 1u;
        if (idx[1] <= g || idx[1] >= n_cells_y + g)
          mask |= 2u;
        if (idx[2] <= g)
          mask |= 4u;
        grid.fixed_components[n] = mask;
      }

    std::vector<double> xs, zs;
    p1_slice(xs, zs);
    const int    n_slices = 2 * n_cells_y;
    const size_t n_slice  = xs.size();
    points.resize(static_cast<int>(n_slice * n_slices));
    const double dx = h / 2;
    const Real   V  = Real(dx * dx * dx);
    size_t       i  = 0;
    for (int j = 0; j < n_slices; ++j)
      for (size_t s = 0; s < n_slice; ++s, ++i)
        {
          const double x[3] = {xs[s], (j + 0.5) * dx, zs[s]};
          for (int d = 0; d < 3; ++d)
            {
              points.position[d][i]                   = Real(x[d]);
              points.velocity[d][i]                   = Real(0);
              points.domain_half_length[d][i]         = Real(0.5 * dx);
              points.initial_domain_half_length[d][i] = Real(0.5 * dx);
            }
          for (int c = 0; c < n_voigt; ++c)
            points.stress[c][i] = points.strain[c][i] = Real(0);
          points.volume[i] = points.initial_volume[i] = V;
          points.mass[i]                              = Real(P1::rho) * V;
          points.plastic_strain[i]                    = Real(0);
          points.material[i]                          = drucker_prager && x[2] < P1::weak_layer ? 1 : 0;
        }

    MaterialParameters<Real> m;
    m.model                  = MaterialModel::linear_elastic;
    m.elastic.youngs_modulus = Real(P1::youngs);
    m.elastic.poissons_ratio = Real(P1::poisson);
    materials.assign(1, m);
    if (drucker_prager)
      {
        const double degree = 3.14159265358979323846 / 180;
        SofteningStrength<Real> &st = m.drucker_prager.strength;
        m.model                     = MaterialModel::drucker_prager;
        st.cohesion                 = Real(20e3);
        st.residual_cohesion        = Real(4e3);
        st.softening_modulus        = Real(60e3 * h);
        st.friction_angle = st.residual_friction_angle = Real(20 * degree);
        st.dilatancy_angle                             = Real(0);
        materials.assign(2, m);
        materials[1].drucker_prager.strength.friction_angle          = Real(7 * degree);
        materials[1].drucker_prager.strength.residual_friction_angle = Real(7 * degree);
        if (mohr_coulomb)
          for (MaterialParameters<Real> &weak_or_not : materials)
            {
              weak_or_not.model                 = MaterialModel::mohr_coulomb;
              weak_or_not.mohr_coulomb.strength = weak_or_not.drucker_prager.strength;
            }
      }
  }

  template <typename Real>
  mpm::StepSettings<3, Real> p1_settings()
  {
    mpm::StepSettings<3, Real> s;
    s.scheme         = mpm::UpdateScheme::musl;
    s.gravity[0]     = s.gravity[1] = s.gravity[2] = Real(0);
    s.damping        = Real(P1::damping);
    s.flip_fraction  = Real(1);
    s.domain_update  = mpm::DomainUpdate::det_F;
    s.mass_tolerance = Real(1e-9 * P1::rho * std::pow(P1::h / 2, 3));
    return s;
  }

  // Gravity of the ramp at time t (z is up).
  template <typename Real>
  void p1_gravity(mpm::StepSettings<3, Real> &s, const double t)
  {
    const double ramp = t < P1::t_ramp ? t / P1::t_ramp : 1.0;
    s.gravity[2]      = Real(-P1::gravity * ramp);
  }

  // Elastic P-wave speed, for the CFL time step dt = cfl h / (c + max |v|).
  inline double p1_wave_speed()
  {
    const double G = P1::youngs / (2 * (1 + P1::poisson));
    const double K = P1::youngs / (3 * (1 - 2 * P1::poisson));
    return std::sqrt((K + 4.0 / 3.0 * G) / P1::rho);
  }
} // namespace mpm_bench
