// Scene drivers shared by the GPU tests, templated on a Target (gpu_targets.h) so that the
// CPU and GPU runs of one scene execute the same host code around the same step.h.
//   column  : tests/core/elastic_column.h (V1, shared with the CPU tests)
//   slump   : P1/V5 slump geometry, reduced to 2 cells across (3D, GIMP, 10,024 points),
//             elastic or Drucker-Prager, gravity ramp, local damping 0.1 (either form), free-slip walls
//             and base
//   collapse: V3 geometry (2D, 0.2 m x 0.1 m column against a wall), h = 5 mm, 2x2 ppc,
//             elastic or Drucker-Prager; no-slip base, rollers on walls, gravity applied at once;
//             or held, the equilibration's damped steps on the grid; or onto a frictional floor
//             at the grid's face that stops the points' centres
//   slide   : 3D elastic block (0.4 x 0.3 x 0.2 m, h = 5 cm, 1,536 points, geostatic stress)
//             thrown at (2, 1, 0) m/s over a frictional base (mu = 0.3) against a frictional
//             wall at x max (mu = 0.5) that it reaches after about 0.05 s and rebounds from
#pragma once

#include "../../benchmarks/p1_scene.h"
#include "../core/elastic_column.h"
#include "gpu_targets.h"

#include <mpm/core/point_generation.h>

#include <cmath>
#include <vector>

namespace mpm_test
{
  struct SceneResult
  {
    long   n_steps = 0;
    double time    = 0;
    double error   = 0; // column: the V1 error norm (full runs only)
  };

  // n_steps of a scene at the adaptive time step cfl h / (c + largest speed); held scenes
  // (s.hold_points) take their first step from the points' momentum, as the equilibration does.
  // all_physics: the device's kernels that hold Hencky's law, Mohr-Coulomb, U's domains and the
  // affine transfers (step.h's DevicePhysics).
  template <int dim, typename SceneTarget>
  SceneResult step_scene(SceneTarget &target, mpm::StepSettings<dim, double> &s, const double cfl, const double h,
                         const double c, const long n_steps, const bool all_physics = false)
  {
    auto        gv = target.grid();
    SceneResult r;
    double      max_speed = 0;
    for (; r.n_steps < n_steps; ++r.n_steps)
      {
        const double dt            = cfl * h / (c + max_speed);
        s.hold_from_point_momentum = s.hold_points && r.n_steps == 0;
        const auto pv              = target.template points_at_step<mpm::GimpShape>(r.n_steps);
        max_speed = (all_physics ? mpm::explicit_step<dim, mpm::GimpShape, mpm::DevicePhysics::all>(
                                     target.backend, gv, pv, target.material_table(), s, dt) :
                                   mpm::explicit_step<dim, mpm::GimpShape>(target.backend, gv, pv,
                                                                           target.material_table(), s, dt))
                      .max_speed;
        r.time += dt;
      }
    target.finish();
    return r;
  }

  // P1 slump geometry, n_cells_y cells across, elastic phase, fixed number of steps.
  template <template <int, typename> class Target, typename Real = double>
  SceneResult slump(const int n_cells_y, mpm::HostPoints<3, Real> &points, const long n_steps,
                    const mpm::HostPoints<3, Real> *initial = nullptr, const double damping = mpm_bench::P1::damping,
                    const bool drucker_prager = false,
                    const mpm::LocalDampingForm damping_form = mpm::LocalDampingForm::per_component,
                    const double damping_threshold = 0, const mpm::ElasticLaw law = mpm::ElasticLaw::jaumann_rate)
  {
    using namespace mpm;
    using mpm_bench::P1;
    HostGrid<3, Real>                     grid;
    std::vector<MaterialParameters<Real>> materials;
    mpm_bench::make_p1(n_cells_y, grid, points, materials, drucker_prager);
    for (MaterialParameters<Real> &m : materials)
      m.elastic_law = law;
    const bool hencky = law == ElasticLaw::hencky;
    if (initial != nullptr)
      points = *initial; // same scene, points given (e.g. reordered)
    StepSettings<3, Real> s = mpm_bench::p1_settings<Real>();
    s.damping               = Real(damping);
    s.damping_form          = damping_form;
    s.damping_threshold     = Real(damping_threshold);
    const double          c = mpm_bench::p1_wave_speed();
    Target<3, Real>       target(grid, points, materials);
    auto                  gv = target.grid();
    SceneResult           r;
    double                max_speed = 0;
    for (; r.n_steps < n_steps; ++r.n_steps)
      {
        const double dt = P1::cfl * P1::h / (c + max_speed);
        mpm_bench::p1_gravity(s, r.time);
        const auto pv = target.template points_at_step<GimpShape>(r.n_steps);
        max_speed = (hencky ? explicit_step<3, GimpShape, DevicePhysics::all>(target.backend, gv, pv,
                                                                              target.material_table(), s, Real(dt)) :
                              explicit_step<3, GimpShape>(target.backend, gv, pv, target.material_table(), s, Real(dt)))
                      .max_speed;
        r.time += dt;
      }
    target.finish();
    return r;
  }

  // V3 geometry (2D), gravity at once; elastic, or V3's Drucker-Prager (c = 0,
  // phi = 19.8 deg, psi = 0: the column starts to fail within the first steps).
  // held: the equilibration's steps instead (StepSettings::hold_points, the grid keeping its
  // velocities from the second step on, damping 0.8, PIC, the Courant number bounded by the
  // points' domains as in the equilibration).
  // flip_fixed_velocity_change: FLIP passes the no-slip base's velocity change to the points.
  // floor_at_face: the base is the grid's face y = 0, a frictional wall (mu = 0.3) that stops
  // the points' centres (StepSettings::wall_faces), with FLIP 0.99 and pressure averaging as in
  // V3's prm (the flow carries centres through this floor where the wall does not stop them,
  // tests/core/test_wall_friction).
  // disconnection_volume_ratio: the material's (material.h, disconnected points).
  // plastic_model (with drucker_prager): Mohr-Coulomb with the same strength instead, or the
  // material family's test member (models/test_von_mises_model.h) with a yield stress of 1.5 kPa,
  // which the column's base exceeds.
  template <template <int, typename> class Target>
  SceneResult collapse(mpm::HostPoints<2, double> &points, const long n_steps,
                       const mpm::HostPoints<2, double> *initial = nullptr, const bool drucker_prager = false,
                       const bool held = false, const mpm::ElasticLaw law = mpm::ElasticLaw::jaumann_rate,
                       const bool floor_at_face = false, const bool flip_fixed_velocity_change = false,
                       const double              disconnection_volume_ratio = 0,
                       const mpm::MaterialModel  plastic_model              = mpm::MaterialModel::drucker_prager)
  {
    using namespace mpm;
    const double h = 0.005, rho = 2650, E = 0.84e6, nu = 0.3, g = 9.81;
    const double cfl = held ? std::sqrt(0.25 / 2) : 0.5; // sqrt(l / (dim h)), l = h / 4
    const double length = 0.5, height = 0.15;
    const int    below  = floor_at_face ? 0 : 2; // cells below the base
    HostGrid<2, double> grid;
    const double        lower[2] = {-2 * h, -below * h};
    const int           cells[2] = {int(std::lround(length / h)) + 4, int(std::lround(height / h)) + below};
    grid.make_dense(lower, h, cells);
    if (floor_at_face)
      {
        grid.friction_faces.assign(grid.mass.size(), 0);
        grid.friction_coefficient[2] = 0.3;
      }
    for (long n = 0; n < long(grid.lattice_to_node.size()); ++n)
      {
        int idx[2];
        grid.lattice_coordinates(n, idx);
        std::uint8_t mask = 0;
        if (idx[0] <= 2 || idx[0] >= cells[0] - 2)
          mask |= 1u; // rollers on the walls
        if (floor_at_face && idx[1] == 0)
          grid.friction_faces[n] = 1u << 2;
        else if (idx[1] <= below)
          mask |= 3u; // no-slip base
        grid.fixed_components[n] = mask;
      }
    points = HostPoints<2, double>();
    BodyDescription<2, double> body{2, rho, {0, 0}, 0};
    const double               lo[2] = {0, 0}, hi[2] = {0.2, 0.1};
    add_points(points, grid, lo, hi, body, [](const double *) { return true; });
    if (initial != nullptr)
      points = *initial;
    MaterialParameters<double> m;
    m.model                  = MaterialModel::linear_elastic;
    m.elastic.youngs_modulus = E;
    m.elastic.poissons_ratio = nu;
    if (drucker_prager)
      {
        m.model                                   = MaterialModel::drucker_prager;
        m.drucker_prager.strength.friction_angle  = 19.8 * 3.14159265358979323846 / 180;
        m.drucker_prager.strength.residual_friction_angle = m.drucker_prager.strength.friction_angle;
        if (plastic_model == MaterialModel::mohr_coulomb)
          {
            m.model                 = MaterialModel::mohr_coulomb;
            m.mohr_coulomb.strength = m.drucker_prager.strength;
          }
        if (plastic_model == MaterialModel::test_von_mises)
          {
            m.model                       = MaterialModel::test_von_mises;
            m.test_von_mises.yield_stress = 1.5e3;
          }
      }
    m.elastic_law                = law;
    m.disconnection_volume_ratio = disconnection_volume_ratio;
    const double c = std::sqrt(m.elastic.p_wave_modulus() / rho);

    StepSettings<2, double> s;
    s.scheme         = UpdateScheme::musl;
    s.gravity[0]     = 0;
    s.gravity[1]     = -g;
    s.damping        = 0;
    s.flip_fraction  = 1.0;
    s.domain_update  = DomainUpdate::det_F;
    s.mass_tolerance = 1e-12 * points.mass[0];
    s.flip_fixed_velocity_change = flip_fixed_velocity_change;
    s.disconnected_points        = disconnection_volume_ratio > 0;
    if (held)
      {
        s.hold_points   = true;
        s.damping       = 0.8;
        s.flip_fraction = 0;
      }
    if (floor_at_face)
      {
        s.flip_fraction      = 0.99;
        s.domain_update      = DomainUpdate::none;
        s.pressure_averaging = true;
        s.wall_faces         = 1u << 2;
      }
    Target<2, double> target(grid, points, {m});
    // The kernels a DeviceEngine would pick for this material and these settings.
    const bool all_physics = materials_need_all_physics(std::vector<MaterialParameters<double>>{m}) ||
                             settings_need_all_physics(s);
    return step_scene<2>(target, s, cfl, h, c, n_steps, all_physics);
  }

  // The slide: frictional walls (wall_friction.h) on the base and on the wall it runs into.
  template <template <int, typename> class Target>
  SceneResult slide(mpm::HostPoints<3, double> &points, const long n_steps,
                    const mpm::HostPoints<3, double> *initial = nullptr)
  {
    using namespace mpm;
    const double h = 0.05, rho = 2000, E = 1e7, nu = 0.3, g = 9.81, cfl = 0.5, height = 0.2;
    HostGrid<3, double> grid;
    const double        lower[3] = {0, 0, 0};
    const int           cells[3] = {20, 16, 8};
    grid.make_dense(lower, h, cells);
    grid.friction_faces.assign(grid.mass.size(), 0);
    grid.friction_coefficient[1] = 0.5; // x max
    grid.friction_coefficient[4] = 0.3; // z min
    for (long n = 0; n < long(grid.lattice_to_node.size()); ++n)
      {
        int idx[3];
        grid.lattice_coordinates(n, idx);
        grid.friction_faces[n] = (idx[0] == cells[0] ? 1u << 1 : 0u) | (idx[2] == 0 ? 1u << 4 : 0u);
      }
    points = HostPoints<3, double>();
    BodyDescription<3, double> body{2, rho, {2, 1, 0}, 0};
    const double               lo[3] = {0.45, 0.1, 0}, hi[3] = {0.85, 0.4, height};
    add_points(points, grid, lo, hi, body, [](const double *) { return true; });
    const double k0 = nu / (1 - nu);
    for (int i = 0; i < points.size(); ++i)
      {
        points.stress[2][i] = -rho * g * (height - points.position[2][i]);
        points.stress[0][i] = points.stress[1][i] = k0 * points.stress[2][i];
      }
    if (initial != nullptr)
      points = *initial;
    MaterialParameters<double> m;
    m.model                  = MaterialModel::linear_elastic;
    m.elastic.youngs_modulus = E;
    m.elastic.poissons_ratio = nu;
    const double c           = std::sqrt(m.elastic.p_wave_modulus() / rho);

    StepSettings<3, double> s;
    s.scheme         = UpdateScheme::musl;
    s.gravity[0]     = 0;
    s.gravity[1]     = 0;
    s.gravity[2]     = -g;
    s.damping        = 0;
    s.flip_fraction  = 1.0;
    s.domain_update  = DomainUpdate::det_F;
    s.mass_tolerance = 1e-12 * points.mass[0];
    Target<3, double> target(grid, points, {m});
    return step_scene<3>(target, s, cfl, h, c, n_steps);
  }
} // namespace mpm_test
