// Coulomb friction of the grid's walls (wall_friction.h, step.h's grid update).
//
// 1. The function on given velocities: a node moving into the wall loses its normal
//    component and its tangential one is reduced by mu times the velocity into the wall,
//    along its own direction, to rest at most; a node leaving the wall is left alone; the
//    kinetic energy never grows.
// 2. An elastic block (plane strain, 1 m long, 0.5 m high, E = 100 MPa, nu = 0, rho = 1000,
//    g = 10, h = 0.125 m, geostatic initial stress: it starts in vertical equilibrium) slides
//    with an initial speed v0 on a base of friction coefficient mu:
//    - on a flat base it stops after d0 = v0^2 / (2 mu g);
//    - on a base tilted by theta (gravity turned by theta) with mu < tan(theta) its centre
//      of mass moves by v0 t + a t^2 / 2 with a = g (sin(theta) - mu cos(theta)).
//    Why these hold in the MPM, and to what tolerance: while every base node slides, the
//    friction the base puts on the block is mu times the sum of the base nodes' normal
//    impulses, that is mu times the normal force N on the base. The centre of mass then
//    decelerates by exactly mu N / M, the rigid block's Coulomb law, whatever the block's
//    shear deformation, as long as N = M g cos(theta). N departs from it through the block's
//    vertical ringing about the MPM's own equilibrium of the geostatic stress (the points'
//    stresses are the continuum's equilibrium, not the discretisation's). At the end of the
//    slide the base sticks and the block's elastic shear strain, at most mu rho g H / G, is
//    released: a further displacement of at most mu rho g H^2 / (2 G) = 2.5e-5 m (3e-5
//    relative), and a last step of v dt.
//    - PIC damps the ringing within the first instants: measured relative errors 2.1e-4 to
//      2.6e-4 with every scheme; the test asks for 1e-3.
//    - Pure FLIP keeps the ringing, and what the points keep of it that the grid does not
//      see (FLIP's null space) reaches the base nodes as velocity into the wall at random:
//      measured 1.3e-3 (flat) and 1.8e-3 (tilted) with MUSL and USF, 2.5e-4 with USL, and
//      1.3e-3 to 3.2e-3 at h = 0.25, 0.125, 0.0625 m with MUSL (noise: it does not converge
//      with h). The test asks for 5e-3.
//    With the friction switched off (free-slip base) the same block slides at v0 without
//    stopping: the test sees the difference.
#include "check.h"
#include "scene_helpers.h"

#include <mpm/core/backend/cpu_backend.h>
#include <mpm/core/point_generation.h>
#include <mpm/core/step.h>
#include <mpm/core/wall_friction.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <vector>

using namespace mpm;
using mpm_test::check;
using mpm_test::check_below;
using mpm_test::Slide;

namespace
{
  void test_function()
  {
    const double mu2[4] = {0.5, 0.5, 0.5, 0.5};
    {
      double v[2] = {2, -0.5}; // into the base (y min, face 2)
      apply_wall_friction<2>(v, 1u << 2, mu2);
      check(v[0] == 2 - 0.5 * 0.5 && v[1] == 0, "base: normal removed, tangential reduced by mu v_n");
    }
    {
      double v[2] = {2, 0.5}; // leaving the base
      apply_wall_friction<2>(v, 1u << 2, mu2);
      check(v[0] == 2 && v[1] == 0.5, "a node leaving the wall is left alone (it separates)");
    }
    {
      double v[2] = {0.1, -1}; // braking larger than the tangential speed
      apply_wall_friction<2>(v, 1u << 2, mu2);
      check(v[0] == 0 && v[1] == 0, "the tangential velocity is brought to rest, never reversed");
    }
    {
      double v[2] = {1, 2}; // into x max (face 1), outward normal +x
      apply_wall_friction<2>(v, 1u << 1, mu2);
      check(v[0] == 0 && v[1] == 2 - 0.5, "upper face: outward normal +e_axis");
    }
    {
      const double mu3[6] = {0, 0, 0, 0, 1, 0};
      double       v[3]   = {3, 4, -1}; // into z min (face 4), tangential speed 5
      apply_wall_friction<3>(v, 1u << 4, mu3);
      check(std::fabs(v[0] - 2.4) < 1e-15 && std::fabs(v[1] - 3.2) < 1e-15 && v[2] == 0,
            "3D: the tangential velocity keeps its direction, its magnitude drops by mu v_n");
    }
    // Friction only removes kinetic energy, for random velocities, masks and coefficients.
    std::mt19937                           rng(3);
    std::uniform_real_distribution<double> u(-1, 1);
    double                                 worst = -1;
    for (int k = 0; k < 10000; ++k)
      {
        double       v[3] = {u(rng), u(rng), u(rng)}, before = 0, after = 0;
        const double mu[6] = {1 + u(rng), 1 + u(rng), 1 + u(rng), 1 + u(rng), 1 + u(rng), 1 + u(rng)};
        for (int d = 0; d < 3; ++d)
          before += v[d] * v[d];
        apply_wall_friction<3>(v, std::uint8_t(rng() % 64), mu);
        for (int d = 0; d < 3; ++d)
          after += v[d] * v[d];
        worst = std::max(worst, after - before);
      }
    check_below(worst, 0.0, "friction never adds kinetic energy");
  }

  struct Method
  {
    UpdateScheme scheme;
    double       flip_fraction;
    double       tolerance; // on the relative error of the distance (header)
    const char  *name;
  };

  // The block on a base of friction mu (0: free-slip) tilted by theta, for t_end.
  Slide slide(const Method &method, const double mu, const double theta, const double v0, const double t_end)
  {
    const double h = 0.125, rho = 1000, E = 1e8, g = 10, height = 0.5, length = 1;
    HostGrid<2, double> grid;
    const double        lower[2] = {0, 0};
    const int           cells[2] = {64, 8};
    grid.make_dense(lower, h, cells);
    if (mu > 0)
      {
        grid.friction_faces.assign(grid.mass.size(), 0);
        grid.friction_coefficient[2] = mu;
      }
    for (long n = 0; n < long(grid.lattice_to_node.size()); ++n)
      {
        int idx[2];
        grid.lattice_coordinates(n, idx);
        if (idx[1] == 0 && mu > 0)
          grid.friction_faces[n] = 1u << 2; // frictional base
        else if (idx[1] == 0)
          grid.fixed_components[n] = 2u; // free-slip base
      }
    HostPoints<2, double>      p;
    BodyDescription<2, double> body{2, rho, {v0, 0}, 0};
    const double               lo[2] = {4 * h, 0}, hi[2] = {4 * h + length, height};
    add_points(p, grid, lo, hi, body, [](const double *) { return true; });
    for (int i = 0; i < p.size(); ++i)
      p.stress[1][i] = -rho * g * std::cos(theta) * (height - p.position[1][i]); // geostatic, K0 = 0

    auto s           = mpm_test::quiet_settings<2>(method.scheme);
    s.gravity[0]     = g * std::sin(theta);
    s.gravity[1]     = -g * std::cos(theta);
    s.domain_update  = DomainUpdate::none;
    s.mass_tolerance = 1e-12 * p.mass[0];
    s.flip_fraction  = method.flip_fraction;
    const std::vector<MaterialParameters<double>> materials = {mpm_test::elastic(E, 0)};
    return mpm_test::slide_along_x(grid, p, materials, s, std::sqrt(E / rho), t_end);
  }

  void test_stopping_distance(const Method &method)
  {
    const double v0 = 2, mu = 0.25, g = 10, d0 = v0 * v0 / (2 * mu * g), t_stop = v0 / (mu * g);
    const Slide  braked = slide(method, mu, 0, v0, 1.5 * t_stop);
    std::printf("%s, flat base, mu = %.2f: the block stops after %.6f m, mean speed %.2e m/s (v0^2 / (2 mu g) = "
                "%.6f m, relative error %.1e, allowed %.0e)\n",
                method.name, mu, braked.distance, braked.speed, d0, std::fabs(braked.distance / d0 - 1),
                method.tolerance);
    check_below(std::fabs(braked.distance / d0 - 1), method.tolerance, "the block stops after v0^2 / (2 mu g)");
    check_below(std::fabs(braked.speed), method.tolerance * v0, "the block is at rest");

    const Slide free = slide(method, 0, 0, v0, 1.5 * t_stop);
    std::printf("%s, free-slip base: after %.2f s the block has slid %.4f m at %.4f m/s\n", method.name,
                1.5 * t_stop, free.distance, free.speed);
    check(std::fabs(free.speed - v0) < 0.01 * v0 && free.distance > 1.4 * t_stop * v0,
          "without friction nothing stops the block", free.distance, 1.5 * t_stop * v0);
  }

  void test_tilted_base(const Method &method)
  {
    const double theta = M_PI / 6, mu = 0.3, g = 10, v0 = 0.5, t_end = 0.5;
    const double a        = g * (std::sin(theta) - mu * std::cos(theta));
    const double expected = v0 * t_end + 0.5 * a * t_end * t_end;
    const Slide  sliding  = slide(method, mu, theta, v0, t_end);
    std::printf("%s, base tilted by 30 deg, mu = %.2f: moved %.6f m at %.6f m/s (rigid Coulomb block: %.6f m at "
                "%.6f m/s, relative error %.1e, allowed %.0e)\n",
                method.name, mu, sliding.distance, sliding.speed, expected, v0 + a * t_end,
                std::fabs(sliding.distance / expected - 1), method.tolerance);
    check_below(std::fabs(sliding.distance / expected - 1), method.tolerance,
                "on a tilted base the block slides by v0 t + g (sin theta - mu cos theta) t^2 / 2");
  }

  // 3. A granular column collapsing onto the base (the V3 column 0.2 m x 0.1 m of
  //    doc/validation-v3.md at h = 5 mm: Drucker-Prager, phi = 19.8 deg, no cohesion, MUSL,
  //    GIMP, FLIP 0.99, pressure averaging). The GIMP weights of the points on the base reach
  //    the nodes one and two cells up, which still move down where the flow runs over its
  //    front, so unless the wall stops them (stop_at_walls) centres are carried through the
  //    base. Returns how many points left the grid by t_end; the lowest centre in lowest_y.
  int points_through_base(const int base, const std::uint8_t walls, double &lowest_y)
  {
    const double h = 0.005, rho = 2650, E = 0.84e6, nu = 0.3, g = 9.81, K0 = 0.4286, width = 0.2, height = 0.1;
    const double t_end = 0.3;
    HostGrid<2, double> grid;
    const double        lower[2] = {0, 0};
    const int           cells[2] = {120, 24};
    grid.make_dense(lower, h, cells);
    grid.friction_faces.assign(grid.mass.size(), 0);
    grid.friction_coefficient[2] = 0.3;
    for (long n = 0; n < long(grid.lattice_to_node.size()); ++n)
      {
        int idx[2];
        grid.lattice_coordinates(n, idx);
        if (idx[0] == 0)
          grid.fixed_components[n] |= 1u; // free-slip back wall
        if (idx[1] == 0)
          {
            if (base == 0)
              grid.friction_faces[n] = 1u << 2;
            else
              grid.fixed_components[n] |= base == 1 ? 2u : 3u; // free-slip, no-slip
          }
      }
    HostPoints<2, double>      p;
    BodyDescription<2, double> body{2, rho, {0, 0}, 0};
    const double               lo[2] = {0, 0}, hi[2] = {width, height};
    add_points(p, grid, lo, hi, body, [](const double *) { return true; });
    for (int i = 0; i < p.size(); ++i)
      {
        p.stress[1][i] = -rho * g * (height - p.position[1][i]); // geostatic
        p.stress[0][i] = p.stress[2][i] = K0 * p.stress[1][i];
      }
    MaterialParameters<double> sand = mpm_test::elastic(E, nu);
    sand.model                                           = MaterialModel::drucker_prager;
    sand.drucker_prager.strength.cohesion                = 0;
    sand.drucker_prager.strength.friction_angle          = 19.8 * M_PI / 180;
    sand.drucker_prager.strength.residual_friction_angle = 19.8 * M_PI / 180;
    sand.drucker_prager.strength.dilatancy_angle         = 0;

    auto s               = mpm_test::quiet_settings<2>(UpdateScheme::musl);
    s.gravity[1]         = -g;
    s.domain_update      = DomainUpdate::none;
    s.mass_tolerance     = 1e-12 * p.mass[0];
    s.flip_fraction      = 0.99;
    s.pressure_averaging = true;
    s.wall_faces         = walls;
    const GridView<2, double> view = grid.view(); // with the averaging's cell sums (make_dense)
    CpuBackend   backend;
    const double c = std::sqrt(E * (1 - nu) / (rho * (1 + nu) * (1 - 2 * nu)));
    double       t = 0, max_speed = 0;
    while (t < t_end)
      {
        const double dt = std::min(0.5 * h / (c + max_speed), t_end - t);
        max_speed = explicit_step<2, GimpShape>(backend, view, p.view(), &sand, s, dt).max_speed;
        t += dt;
      }
    int removed = 0;
    lowest_y    = 1e300;
    for (int i = 0; i < p.size(); ++i)
      if (p.material[i] < 0)
        ++removed;
      else
        lowest_y = std::min(lowest_y, p.position[1][i]);
    return removed;
  }

  void test_points_stop_at_walls()
  {
    const std::uint8_t walls    = (1u << 0) | (1u << 2); // x min and y min
    const char        *names[3] = {"frictional", "free-slip", "no-slip"};
    for (int base = 0; base < 3; ++base)
      {
        double    lowest_wall;
        const int held = points_through_base(base, walls, lowest_wall);
        std::printf("column collapsing onto a %s base, the walls stopping the points: %d points left the grid, "
                    "lowest centre %.3e m\n",
                    names[base], held, lowest_wall);
        check(held == 0 && lowest_wall >= 0, "no point's centre passes a wall", held, lowest_wall);
      }
    // Without (the walls' nodes held, the points' centres not), the frictional base lets
    // points through: what the check above guards against.
    double    lowest_open;
    const int open = points_through_base(0, 0, lowest_open);
    std::printf("the same on the frictional base without stopping the points: %d points left the grid\n", open);
    check(open > 0, "without stopping the centres the flow carries points through the base", open);
  }
} // namespace

int main()
{
  test_function();
  test_points_stop_at_walls();
  const Method methods[] = {{UpdateScheme::musl, 0, 1e-3, "MUSL, PIC"},  {UpdateScheme::usl, 0, 1e-3, "USL, PIC"},
                            {UpdateScheme::usf, 0, 1e-3, "USF, PIC"},    {UpdateScheme::musl, 1, 5e-3, "MUSL, FLIP"},
                            {UpdateScheme::usl, 1, 5e-3, "USL, FLIP"},   {UpdateScheme::usf, 1, 5e-3, "USF, FLIP"}};
  for (const Method &method : methods)
    {
      test_stopping_distance(method);
      test_tilted_base(method);
    }
  return mpm_test::finish("test_wall_friction");
}
