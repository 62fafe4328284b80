// A free elastic block spinning rigidly about its centre (no gravity, no walls): a square
// in 2D, a cube in 3D turning about z. After a quarter turn each cpGIMP domain update shows
// what it does under rotation: F_ii = cos(90 deg) drives the domain to nothing, U (the
// stretch of F = R U) leaves it as it was. Templated on the Target (targets.h) so that the
// CPU test and the GPU agreement test run the same scene.
#pragma once

#include "targets.h"

#include <mpm/core/point_generation.h>
#include <mpm/core/step.h>

#include <algorithm>
#include <cmath>
#include <vector>

namespace mpm_test
{
  struct SpinResult
  {
    double min_scale = 1e300, max_scale = 0; // domain half-length over its initial value
    double angle        = 0;                 // mean rotation of the points about the axis (rad)
    double energy_ratio = 0;                 // kinetic energy, final over initial
    double momentum_ratio = 0;               // angular momentum about the axis, final over initial
    long   n_steps      = 0;
  };

  // The velocity transfer: the FLIP/PIC blend (flip_fraction), or an affine transfer, TPIC or
  // APIC by `affine` (affine matrix in the points' first dim x dim state variables, flip_fraction 0).
  struct Transfer
  {
    double            flip_fraction = 1;
    bool              apic          = false;
    mpm::AffineMatrix affine        = mpm::AffineMatrix::velocity_gradient;
    mpm::UpdateScheme scheme        = mpm::UpdateScheme::musl;
  };

  // Spins the block by `turn` radians at 2 rad/s; `points` receives the final state,
  // `initial` (if given) replaces the generated points; max_steps < 0: run the whole turn.
  template <int dim, typename Shape, template <int, typename> class Target = CpuTarget>
  SpinResult spinning_block(const mpm::DomainUpdate update, mpm::HostPoints<dim, double> &points,
                            const double turn = M_PI / 2, const long max_steps = -1,
                            const mpm::HostPoints<dim, double> *initial = nullptr, const Transfer transfer = {})
  {
    using namespace mpm;
    const double E = 1e6, nu = 0.3, rho = 1000, omega = 2, h = 0.125;
    const double c = std::sqrt(E * (1 - nu) / ((1 + nu) * (1 - 2 * nu)) / rho); // P wave
    const int    n = dim == 2 ? 32 : 24; // cells per side
    const double side = 1.5, centre = n * h / 2;

    HostGrid<dim, double> grid;
    double                lower[dim], lo[dim], hi[dim];
    int                   cells[dim];
    for (int d = 0; d < dim; ++d)
      {
        lower[d] = 0;
        cells[d] = n;
        lo[d]    = centre - side / 2;
        hi[d]    = centre + side / 2;
      }
    grid.make_dense(lower, h, cells);
    std::fill(grid.fixed_components.begin(), grid.fixed_components.end(), 0u);

    points = HostPoints<dim, double>();
    BodyDescription<dim, double> body{2, rho, {}, 0};
    add_points(points, grid, lo, hi, body, [](const double *) { return true; });
    for (int i = 0; i < points.size(); ++i)
      {
        points.velocity[0][i] = -omega * (points.position[1][i] - centre);
        points.velocity[1][i] = omega * (points.position[0][i] - centre);
      }
    if (initial != nullptr)
      points = *initial;
    if (transfer.apic) // C = the spin's velocity gradient: [[0, -omega], [omega, 0]] in the xy plane
      {
        points.set_n_state_variables(dim * dim);
        std::fill(points.state_variables[1].begin(), points.state_variables[1].end(), -omega);
        std::fill(points.state_variables[dim].begin(), points.state_variables[dim].end(), omega);
      }
    // CPDI2q's corners after the affine matrix: offsets from the rectangle, zero at the start
    const int corner = transfer.apic ? dim * dim : 0;
    if constexpr (Shape::tracks_corners)
      if (points.n_state_variables() < corner + (1 << dim) * dim)
        points.set_n_state_variables(corner + (1 << dim) * dim);
    const std::vector<double> x0 = points.position[0], y0 = points.position[1];
    auto kinetic = [&]() {
      double k = 0;
      for (int i = 0; i < points.size(); ++i)
        for (int d = 0; d < dim; ++d)
          k += 0.5 * points.mass[i] * points.velocity[d][i] * points.velocity[d][i];
      return k;
    };
    auto angular_momentum = [&]() {
      double l = 0;
      for (int i = 0; i < points.size(); ++i)
        l += points.mass[i] * ((points.position[0][i] - centre) * points.velocity[1][i] -
                               (points.position[1][i] - centre) * points.velocity[0][i]);
      return l;
    };
    const double k0 = kinetic(), l0 = angular_momentum();

    MaterialParameters<double> material{};
    material.model                  = MaterialModel::linear_elastic;
    material.elastic.youngs_modulus = E;
    material.elastic.poissons_ratio = nu;

    StepSettings<dim, double> s;
    s.scheme = transfer.scheme;
    for (int d = 0; d < dim; ++d)
      s.gravity[d] = 0;
    s.damping        = 0;
    s.flip_fraction  = transfer.apic ? 0 : transfer.flip_fraction;
    s.affine_state_variable = transfer.apic ? 0 : -1;
    s.affine_matrix         = transfer.affine;
    s.corner_state_variable = Shape::tracks_corners ? corner : -1;
    s.domain_update  = update;
    s.mass_tolerance = 1e-12 * points.mass[0];

    SpinResult   r;
    const double t_end = turn / omega;
    double       time  = 0;
    {
      Target<dim, double> target(grid, points, {material});
      auto                gv        = target.grid();
      double              max_speed = 0;
      while (time < t_end - 1e-12 && (max_steps < 0 || r.n_steps < max_steps))
        {
          const double dt = std::min(0.5 * h / (c + max_speed), t_end - time);
          const auto   pv = target.template points_at_step<Shape>(r.n_steps);
          // The affine transfers and U's domains: on the device, the step's kernels that hold them.
          max_speed = (transfer.apic || update == DomainUpdate::U ?
                         explicit_step<dim, Shape, DevicePhysics::all>(target.backend, gv, pv, target.material_table(),
                                                                       s, dt) :
                         explicit_step<dim, Shape>(target.backend, gv, pv, target.material_table(), s, dt))
                        .max_speed;
          time += dt;
          ++r.n_steps;
        }
      target.finish();
    }

    for (int i = 0; i < points.size(); ++i)
      {
        for (int d = 0; d < dim; ++d)
          {
            const double scale = points.domain_half_length[d][i] / points.initial_domain_half_length[d][i];
            r.min_scale        = std::min(r.min_scale, scale);
            r.max_scale        = std::max(r.max_scale, scale);
          }
        const double a0 = std::atan2(y0[i] - centre, x0[i] - centre);
        const double a1 = std::atan2(points.position[1][i] - centre, points.position[0][i] - centre);
        r.angle += std::remainder(a1 - a0, 2 * M_PI) / points.size();
      }
    r.energy_ratio   = kinetic() / k0;
    r.momentum_ratio = angular_momentum() / l0;
    return r;
  }
} // namespace mpm_test
