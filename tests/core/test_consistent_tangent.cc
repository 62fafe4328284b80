// The consistent tangents (consistent_tangent.h) against central finite differences of the
// update they differentiate, sigma(d_eps) = return_mapping(trial + D d_eps), in every return
// region, each case asserting the region it lands in (so that no check passes vacuously):
//  - elastic (D itself, also for Mohr-Coulomb inside the surface);
//  - Drucker-Prager: cone (shear), tension cut-off, corner of the two;
//  - Mohr-Coulomb: plane, compression edge, extension edge, apex, and a trial stress with two
//    equal principal stresses (the rotation term's limit), on principal axes rotated off the
//    coordinate axes;
//  - the stress the tangent functions return equals the plain return mapping's to the last bit;
//  - small_strain_update (the FEM stage's point update) gives the MPM's update_stress with no
//    spin to the last bit, stress and plastic strain, over 3,000 random states and increments of
//    elastic, Drucker-Prager and Mohr-Coulomb materials with softening, plasticity on and off;
//    a user model is refused (it gives no tangent).
// Tolerance: 1e-6 of the largest elastic stiffness entry. The differences use a strain step of 1e-9 around
// increments that keep every perturbed state in the same region; their error is about
// 1e-16 |sigma| / 1e-9 ~ 1e-2 Pa against entries of ~1e7 Pa (1e-9 relative), and a region
// boundary crossed inside the stencil would show as an O(1) error.
#include <mpm/core/material/consistent_tangent.h>
#include <mpm/core/material/small_strain_update.h>

#include "check.h"

#include <algorithm>
#include <cstdio>
#include <functional>
#include <random>
#include <string>

using namespace mpm;
using mpm_test::check;
using mpm_test::check_below;

namespace
{
  constexpr double deg = 3.14159265358979323846 / 180;

  const LinearElasticParameters<double> elastic{2e7, 0.3};

  // A stress with principal values s on axes rotated by a fixed rotation (not the coordinate axes).
  SymTensor<double> rotated(const double s0, const double s1, const double s2)
  {
    const double a = 0.4, b = -0.7, c = 1.1; // Euler-like angles
    Mat3<double> Rx = Mat3<double>::identity(), Ry = Mat3<double>::identity(), Rz = Mat3<double>::identity();
    Rx.a[1][1] = Rx.a[2][2] = std::cos(a);
    Rx.a[1][2]              = -std::sin(a);
    Rx.a[2][1]              = std::sin(a);
    Ry.a[0][0] = Ry.a[2][2] = std::cos(b);
    Ry.a[0][2]              = std::sin(b);
    Ry.a[2][0]              = -std::sin(b);
    Rz.a[0][0] = Rz.a[1][1] = std::cos(c);
    Rz.a[0][1]              = -std::sin(c);
    Rz.a[1][0]              = std::sin(c);
    const Mat3<double> R = multiply(Rz, multiply(Ry, Rx));
    Mat3<double>       S{};
    const double       s[3] = {s0, s1, s2};
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j)
        {
          S.a[i][j] = 0;
          for (int k = 0; k < 3; ++k)
            S.a[i][j] += R.a[i][k] * s[k] * R.a[j][k];
        }
    return symmetric_part(S);
  }

  using Update = std::function<SymTensor<double>(const SymTensor<double> &trial)>;

  // Largest |C - C_fd| over max |D| (the apex's C is zero), the finite differences of
  // update(trial + D d_eps) at d_eps = 0.
  double tangent_error(const SymTensor<double> &trial, const Tangent C, const Update &update)
  {
    const double step = 1e-9;
    Tangent      D;
    elastic_tangent(elastic, D);
    double worst = 0, largest = 0;
    for (int j = 0; j < n_voigt; ++j)
      {
        SymTensor<double> unit = SymTensor<double>::zero();
        unit[j]                = step;
        const SymTensor<double> d = elastic_stress_increment(elastic, unit);
        SymTensor<double>       plus = trial, minus = trial;
        for (int c = 0; c < n_voigt; ++c)
          {
            plus[c] += d[c];
            minus[c] -= d[c];
          }
        const SymTensor<double> up = update(plus), down = update(minus);
        for (int i = 0; i < n_voigt; ++i)
          {
            worst   = std::max(worst, std::abs(C[i][j] - (up[i] - down[i]) / (2 * step)));
            largest = std::max(largest, std::abs(D[i][j]));
          }
      }
    return worst / largest;
  }

  void report(const std::string &what, const double error, const bool region, const bool same_stress)
  {
    std::printf("%-46s tangent vs finite differences %.2e\n", what.c_str(), error);
    check(region, (what + ": the trial stress lands in this return region").c_str());
    check(same_stress, (what + ": the stress equals the return mapping's to the last bit").c_str());
    check_below(error, 1e-6, (what + ": tangent matches finite differences").c_str());
  }

  struct Case
  {
    const char       *name;
    SymTensor<double> trial;
    ReturnMode        mode;
  };

  // Each case: the region it lands in, the stress against the plain update, the tangent against
  // finite differences. tangent(stress, C) returns the trial stress and fills C.
  template <std::size_t n, typename TangentFunction>
  void check_cases(const Case (&cases)[n], const Update &update, TangentFunction &&tangent)
  {
    for (const Case &c : cases)
      {
        SymTensor<double>          s = c.trial;
        Tangent                    C;
        const ReturnResult<double> r     = tangent(s, C);
        const SymTensor<double>    plain = update(c.trial);
        bool                       same  = true;
        for (int i = 0; i < n_voigt; ++i)
          same = same && s[i] == plain[i];
        report(c.name, tangent_error(c.trial, C, update), r.mode == c.mode, same);
      }
  }

  void drucker_prager_cases()
  {
    SofteningStrength<double> strength;
    strength.cohesion        = 2e4;
    strength.friction_angle  = 30 * deg;
    strength.dilatancy_angle = 10 * deg;
    const DruckerPragerCoefficients<double> k = drucker_prager_coefficients(current_strength(strength, 0.0), 5e3);
    const Update update = [&](const SymTensor<double> &trial) {
      SymTensor<double> s = trial;
      drucker_prager_return(elastic, k, s);
      return s;
    };
    const Case cases[] = {
      {"Drucker-Prager, elastic", rotated(-2e4, -3e4, -4e4), ReturnMode::elastic},
      {"Drucker-Prager, cone", rotated(-1e4, -6e4, -1.6e5), ReturnMode::shear},
      {"Drucker-Prager, tension cut-off", rotated(1.2e4, 1.0e4, 0.9e4), ReturnMode::tension},
      {"Drucker-Prager, corner (cone and cut-off)", rotated(6e4, 1e4, -1e4), ReturnMode::corner},
    };
    check_cases(cases, update, [&](SymTensor<double> &stress, Tangent C) {
      return drucker_prager_tangent(elastic, k, stress, C);
    });
  }

  void mohr_coulomb_cases()
  {
    SofteningStrength<double> strength;
    strength.cohesion        = 2e4;
    strength.friction_angle  = 30 * deg;
    strength.dilatancy_angle = 10 * deg;
    const CurrentStrength<double> current = current_strength(strength, 0.0);
    const Update update = [&](const SymTensor<double> &trial) {
      SymTensor<double> s = trial;
      mohr_coulomb_return(elastic, current, s);
      return s;
    };
    const Case cases[] = {
      {"Mohr-Coulomb, elastic", rotated(-2e4, -3e4, -4e4), ReturnMode::elastic},
      {"Mohr-Coulomb, plane", rotated(-1e4, -6e4, -1.6e5), ReturnMode::shear},
      {"Mohr-Coulomb, compression edge", rotated(-2e4, -2.6e4, -1.8e5), ReturnMode::edge_compression},
      {"Mohr-Coulomb, extension edge", rotated(-1e4, -1.5e5, -1.6e5), ReturnMode::edge_extension},
      {"Mohr-Coulomb, extension edge, sigma_2 = sigma_3", rotated(-1e4, -1.5e5, -1.5e5), ReturnMode::edge_extension},
      {"Mohr-Coulomb, apex", rotated(6e4, 5e4, 4e4), ReturnMode::apex},
    };
    check_cases(cases, update, [&](SymTensor<double> &stress, Tangent C) {
      return mohr_coulomb_tangent(elastic, current, stress, C);
    });
  }

  void small_strain_update_is_the_mpm_update()
  {
    SofteningStrength<double> strength;
    strength.cohesion                = 2e4;
    strength.residual_cohesion       = 5e3;
    strength.softening_modulus       = 1e6;
    strength.friction_angle          = 30 * deg;
    strength.residual_friction_angle = 25 * deg;
    strength.dilatancy_angle         = 10 * deg;
    MaterialParameters<double> materials[3] = {};
    for (auto &m : materials)
      m.elastic = elastic;
    materials[0].model                          = MaterialModel::linear_elastic;
    materials[1].model                          = MaterialModel::drucker_prager;
    materials[1].drucker_prager.strength        = strength;
    materials[1].drucker_prager.tensile_strength = 5e3;
    materials[2].model                          = MaterialModel::mohr_coulomb;
    materials[2].mohr_coulomb.strength          = strength;

    std::mt19937                           random(7);
    std::uniform_real_distribution<double> stress_value(-2e5, 3e4), strain_value(-4e-3, 4e-3), eps_p(0, 0.02);
    int                                    differ = 0, plastic = 0, n = 0;
    for (int trial = 0; trial < 1000; ++trial)
      for (MaterialParameters<double> m : materials)
        {
          m.plasticity_enabled = trial % 4 != 0;
          SymTensor<double> sigma, d_eps;
          for (int c = 0; c < n_voigt; ++c)
            {
              sigma[c] = stress_value(random) * (c < 3 ? 1.0 : 0.3);
              d_eps[c] = strain_value(random);
            }
          const double             e0 = eps_p(random);
          MaterialPointState<double> mpm{sigma, e0};
          update_stress(m, d_eps, Mat3<double>{}, mpm);
          SymTensor<double> fem = sigma;
          double            e   = e0;
          Tangent           C;
          const ReturnResult<double> r = small_strain_update(m, d_eps, fem, e, C);
          plastic += r.mode != ReturnMode::elastic;
          bool same = e == mpm.plastic_strain;
          for (int c = 0; c < n_voigt; ++c)
            same = same && fem[c] == mpm.stress[c];
          differ += !same;
          ++n;
        }
    std::printf("small_strain_update against update_stress with no spin: %d of %d states differ, %d plastic\n",
                differ, n, plastic);
    check(differ == 0, "small_strain_update gives the MPM's update to the last bit");
    check(plastic > n / 4, "a good share of the states return plastically", plastic, n / 4);

    MaterialParameters<double> user = materials[0];
    user.model                      = MaterialModel::user_defined;
    SymTensor<double> sigma         = SymTensor<double>::zero(), d_eps = SymTensor<double>::zero();
    double            e             = 0;
    Tangent           C;
    bool              refused = false;
    try
      {
        small_strain_update(user, d_eps, sigma, e, C);
      }
    catch (const std::invalid_argument &)
      {
        refused = true;
      }
    check(refused, "small_strain_update refuses a user model (no tangent)");
  }
} // namespace

int main()
{
  // The elastic tangent is D: sigma_xy = 2 G eps_xy (tensor shears).
  Tangent D;
  elastic_tangent(elastic, D);
  check(std::abs(D[3][3] - 2 * elastic.shear_modulus()) < 1e-9 * D[3][3], "elastic tangent: C_xyxy = 2 G");
  check(std::abs(D[0][1] - (elastic.bulk_modulus() - 2.0 / 3 * elastic.shear_modulus())) < 1e-9 * D[0][0],
        "elastic tangent: C_xxyy = lambda");
  drucker_prager_cases();
  mohr_coulomb_cases();
  small_strain_update_is_the_mpm_update();
  return mpm_test::finish("test_consistent_tangent");
}
