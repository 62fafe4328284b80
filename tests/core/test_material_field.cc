// Per-point material parameters (random fields): a point's field value replaces the
// material's parameter (cohesion keeps the c_res/c ratio, friction angle keeps phi - phi_res),
// and a step with a uniform field equals, bit for bit, the step with that value in the
// material; a different field value changes the result.
#include <mpm/core/backend/cpu_backend.h>
#include <mpm/core/point_generation.h>
#include <mpm/core/step.h>

#include "check.h"
#include "scene_helpers.h"

using namespace mpm;

namespace
{
  MaterialParameters<double> drucker_prager(const double c)
  {
    MaterialParameters<double> m = mpm_test::elastic(1e6, 0.3);
    m.model                                     = MaterialModel::drucker_prager;
    m.drucker_prager.strength.cohesion          = c;
    m.drucker_prager.strength.residual_cohesion = c / 4;
    m.drucker_prager.strength.softening_modulus = 5e4;
    m.drucker_prager.strength.friction_angle    = 20 * M_PI / 180;
    m.drucker_prager.strength.residual_friction_angle = 20 * M_PI / 180;
    return m;
  }

  // A block slumping under gravity onto a no-slip base; returns the points after n steps.
  HostPoints<2, double> slump(const MaterialParameters<double> &material, const double field_value)
  {
    HostGrid<2, double> grid;
    const double        lower[2] = {0, 0};
    const int           cells[2] = {24, 12};
    grid.make_dense(lower, 0.1, cells);
    for (long n = 0; n < long(grid.lattice_to_node.size()); ++n)
      {
        int idx[2];
        grid.lattice_coordinates(n, idx);
        if (idx[1] == 0)
          grid.fixed_components[n] = 3u;
      }
    HostPoints<2, double>      points;
    BodyDescription<2, double> body{2, 2000.0, {0, 0}, 0};
    const double               lo[2] = {0.4, 0.0}, hi[2] = {1.2, 0.8};
    add_points(points, grid, lo, hi, body, [](const double *) { return true; });
    for (auto &v : points.material_field)
      v = field_value;
    auto s       = mpm_test::quiet_settings<2>(UpdateScheme::musl);
    s.gravity[1] = -9.81;
    CpuBackend backend;
    auto       g = grid.view();
    auto       p = points.view();
    for (int step = 0; step < 300; ++step)
      explicit_step<2, GimpShape>(backend, g, p, &material, s, 2e-4);
    return points;
  }
} // namespace

int main()
{
  // The replacement rules.
  MaterialParameters<double> m = drucker_prager(20e3);
  m.field_parameter            = FieldParameter::cohesion;
  MaterialParameters<double> f = with_field_value(m, 30e3);
  mpm_test::check(f.drucker_prager.strength.cohesion == 30e3, "field replaces the cohesion");
  mpm_test::check(std::abs(f.drucker_prager.strength.residual_cohesion - 7.5e3) < 1e-9, "c_res keeps its ratio");
  m.field_parameter = FieldParameter::friction_angle;
  f                 = with_field_value(m, 25 * M_PI / 180);
  mpm_test::check(std::abs(f.drucker_prager.strength.friction_angle - 25 * M_PI / 180) < 1e-15, "field replaces phi");
  m.field_parameter = FieldParameter::youngs_modulus;
  f                 = with_field_value(m, 3e6);
  mpm_test::check(f.elastic.youngs_modulus == 3e6, "field replaces E");

  // Through the step: a uniform field equals the plain material; another value differs.
  MaterialParameters<double> plain = drucker_prager(2e3), fielded = drucker_prager(9e9);
  fielded.field_parameter          = FieldParameter::cohesion;
  fielded.drucker_prager.strength.residual_cohesion = 9e9 / 4; // ratio 1/4, as in plain
  const HostPoints<2, double> a = slump(plain, 0.0), b = slump(fielded, 2e3), c = slump(fielded, 4e3);
  double same = 0, differ = 0, eps_p = 0;
  for (int i = 0; i < a.size(); ++i)
    {
      same   = std::max(same, std::abs(a.position[0][i] - b.position[0][i]) + std::abs(a.stress[1][i] - b.stress[1][i]));
      differ = std::max(differ, std::abs(a.stress[3][i] - c.stress[3][i]));
      eps_p  = std::max(eps_p, a.plastic_strain[i]);
    }
  std::printf("uniform field vs material value: max difference %.1e; field 4 kPa vs 2 kPa: shear stress differs by "
              "%.3e Pa; max plastic strain %.2e\n",
              same, differ, eps_p);
  mpm_test::check(eps_p > 0, "the block yields (the cohesion matters)");
  mpm_test::check(same == 0, "uniform field equals the material value, bit for bit", same, 0);
  mpm_test::check(differ > 1.0, "another field value changes the stresses", differ, 1.0);
  return mpm_test::finish("test_material_field");
}
