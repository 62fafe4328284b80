// The material family (material_family.h) through its test member, J2 plasticity without
// hardening (models/test_von_mises_model.h: one file and one line in the family's list), on
// the CPU:
//  - the MPM's update (update_stress, Jaumann rate, no spin) under pure shear: tau = 2 G eps_xy
//    up to tau = sigma_y / sqrt(3), then tau stays there, the normal stresses stay zero and the
//    equivalent plastic strain is 2 / sqrt(3) (eps_xy - eps_y), all to round-off;
//  - the device's standard kernels leave it out (NaN stress) and materials_need_all_physics asks
//    for the variant that has it;
//  - the FEM stage's update (small_strain_update) gives the MPM's stress to the last bit, and its
//    consistent tangent (dual numbers through the return mapping) matches central differences,
//    on the yield surface and inside it;
//  - strength reduction divides sigma_y by F, float conversion keeps it;
//  - a test member is not among the names a user sees.
#include <mpm/core/material/material.h>
#include <mpm/core/material/small_strain_update.h>
#include <mpm/core/material/strength_reduction.h>
#include <mpm/core/precision.h>
#include <mpm/core/step/settings.h>

#include "check.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

using namespace mpm;
using mpm_test::check;
using mpm_test::check_below;

namespace
{
  const double E = 2e7, nu = 0.3, sigma_y = 3e4;
  const double G = E / (2 * (1 + nu));

  MaterialParameters<double> von_mises()
  {
    MaterialParameters<double> m{};
    m.model                       = MaterialModel::test_von_mises;
    m.elastic                     = {E, nu};
    m.test_von_mises.yield_stress = sigma_y;
    return m;
  }

  // Pure shear in n increments up to eps_xy = total; checks the stress after each.
  double worst_shear_error(const MaterialParameters<double> &m)
  {
    const int    n = 300;
    const double eps_y = sigma_y / std::sqrt(3.0) / (2 * G), total = 3 * eps_y, d = total / n;
    MaterialPointState<double> state{SymTensor<double>::zero(), 0.0};
    double                     worst = 0;
    for (int i = 1; i <= n; ++i)
      {
        const double      eps   = i * d;
        SymTensor<double> d_eps = SymTensor<double>::zero();
        d_eps[3]                = d;
        update_stress(m, d_eps, Mat3<double>{}, state);
        const double tau      = std::min(2 * G * eps, sigma_y / std::sqrt(3.0));
        const double eps_p    = eps > eps_y ? 2 / std::sqrt(3.0) * (eps - eps_y) : 0.0;
        double       normal   = 0;
        for (int c : {0, 1, 2, 4, 5})
          normal = std::max(normal, std::abs(state.stress[c]));
        worst = std::max({worst, std::abs(state.stress[3] - tau) / sigma_y, normal / sigma_y,
                          std::abs(state.plastic_strain - eps_p) / total});
      }
    return worst;
  }
} // namespace

int main()
{
  const MaterialParameters<double> m = von_mises();

  // The MPM's update under pure shear.
  {
    const double e = worst_shear_error(m);
    std::printf("pure shear, Jaumann: largest error %.2e of sigma_y\n", e);
    check_below(e, 1e-12, "pure shear: the J2 return gives tau = min(2 G eps, sigma_y / sqrt 3) and its eps_p");
  }

  // The standard device kernels leave the member out; the dispatcher asks for the all variant.
  {
    MaterialPointState<double> state{SymTensor<double>::zero(), 0.0};
    SymTensor<double>          d_eps = SymTensor<double>::zero();
    d_eps[3]                         = 1e-4;
    update_stress<false>(m, d_eps, Mat3<double>{}, state);
    check(std::isnan(state.stress[3]), "the standard kernels' variant gives NaN for a member outside them");
    check(materials_need_all_physics(std::vector<MaterialParameters<double>>{m}),
          "materials_need_all_physics asks for the all variant");
    MaterialParameters<double> dp = m;
    dp.model                      = MaterialModel::drucker_prager;
    check(!materials_need_all_physics(std::vector<MaterialParameters<double>>{dp}),
          "Drucker-Prager stays in the standard kernels");
  }

  // The FEM stage: the same stress to the last bit, and the tangent against differences.
  {
    int    compared = 0, plastic = 0;
    double worst    = 0;
    for (int i = 0; i < 200; ++i)
      {
        const double      a = 1e-4 * std::sin(0.7 * i), b = 1e-4 * std::cos(1.3 * i), c = 2e-4 * std::sin(2.1 * i);
        SymTensor<double> start = SymTensor<double>::zero(), d_eps = SymTensor<double>::zero();
        start[0] = -2e4 + 5e3 * std::sin(0.3 * i);
        start[3] = 1.6e4 * std::cos(0.9 * i);
        d_eps[0] = a, d_eps[1] = b, d_eps[3] = c, d_eps[5] = a * b / 1e-4;
        MaterialPointState<double> mpm_state{start, 0.0};
        update_stress(m, d_eps, Mat3<double>{}, mpm_state);
        SymTensor<double> fem_stress = start;
        double            fem_eps_p  = 0;
        Tangent           C;
        const ReturnResult<double> r = small_strain_update(m, d_eps, fem_stress, fem_eps_p, C);
        plastic += r.mode != ReturnMode::elastic;
        for (int k = 0; k < n_voigt; ++k)
          compared += fem_stress[k] == mpm_state.stress[k];
        compared += fem_eps_p == mpm_state.plastic_strain;
        // central differences of the stress over each strain component
        const double step = 1e-10;
        for (int j = 0; j < n_voigt; ++j)
          {
            SymTensor<double> up = d_eps, down = d_eps;
            up[j] += step, down[j] -= step;
            SymTensor<double> s_up = start, s_down = start;
            double            e_up = 0, e_down = 0;
            Tangent           ignored;
            small_strain_update(m, up, s_up, e_up, ignored);
            small_strain_update(m, down, s_down, e_down, ignored);
            for (int k = 0; k < n_voigt; ++k)
              worst = std::max(worst, std::abs((s_up[k] - s_down[k]) / (2 * step) - C[k][j]) / (2 * G));
          }
      }
    std::printf("FEM stage: %d of 200 increments plastic; tangent error %.2e of 2G\n", plastic, worst);
    check(plastic > 50 && plastic < 200, "the increments reach both the elastic and the plastic region");
    check(compared == 200 * (n_voigt + 1), "small_strain_update gives update_stress's stress and eps_p bit for bit");
    check_below(worst, 1e-5, "the consistent tangent matches central differences");
  }

  // Strength reduction and float.
  {
    const MaterialParameters<double> reduced = with_reduced_strength(m, 2.0);
    check(reduced.test_von_mises.yield_stress == sigma_y / 2, "strength reduction divides sigma_y by F");
    const MaterialParameters<float> f = converted<float>(m);
    check(f.test_von_mises.yield_stress == float(sigma_y) && f.model == MaterialModel::test_von_mises,
          "float conversion carries the member's parameters");
  }

  // A user sees only the members owned by `always`.
  {
    const std::string names = built_in_model_names([](auto) { return true; });
    std::printf("built-in models a user sees: %s\n", names.c_str());
    check(names.find("test von mises") == std::string::npos && names.find("drucker prager") != std::string::npos,
          "the test member is not among the user's models (the built-in ones are)");
  }

  if (mpm_test::failures() > 0)
    return 1;
  std::printf("all checks passed\n");
  return 0;
}
