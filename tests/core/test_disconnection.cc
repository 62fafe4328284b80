// Disconnected points (material.h, MaterialParameters::disconnection_volume_ratio), driven
// through the MPM step's update_stress by a uniaxial path F = diag(s, 1, 1) in many
// increments (f = F_{k+1} F_k^-1, L dt = f - I, J = s):
// - linear elastic, ratio 2, stretched to s = 3 and compressed back to s = 0.5: the stress is
//   exactly zero in every step that ends beyond J = 2, and once back below it is the elastic
//   sum of the increments since the crossing alone, sigma_xx = (lambda + 2G) sum d_eps_xx,
//   sigma_yy = lambda sum d_eps_xx (the Jaumann form has no spin here), to round-off;
// - ratio 0 is the model as it was: the same path gives the sum over every increment;
// - Drucker-Prager (c = 0) stretched: its plastic strain grows at the tension cut-off while
//   connected and not at all beyond the ratio;
// - the prm's allowed values are checked in the deal.II layer (prm/bad/disconnection_ratio_below_one).
#include <mpm/core/material/material.h>

#include "check.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

using namespace mpm;

namespace
{
  struct Step
  {
    double J_new, d_eps_xx, stress_xx, stress_yy, plastic_strain;
  };

  // From s_from to s_to in n equal steps of s; the state after each.
  std::vector<Step> drive(const MaterialParameters<double> &m, const double s_from, const double s_to, const int n,
                          MaterialPointState<double> &state)
  {
    std::vector<Step> steps;
    for (int k = 0; k < n; ++k)
      {
        const double s0 = s_from + (s_to - s_from) * k / n, s1 = s_from + (s_to - s_from) * (k + 1) / n;
        StepKinematics<double> kin;
        kin.f         = Mat3<double>::identity();
        kin.f.a[0][0] = s1 / s0;
        kin.d_spin    = Mat3<double>::zero();
        kin.d_eps     = SymTensor<double>::zero();
        kin.d_eps[0]  = s1 / s0 - 1;
        kin.J         = s0;
        kin.J_new     = s1;
        update_stress(m, kin, state);
        steps.push_back({s1, kin.d_eps[0], state.stress[0], state.stress[1], state.plastic_strain});
      }
    return steps;
  }

  MaterialPointState<double> at_rest()
  {
    MaterialPointState<double> state;
    state.stress         = SymTensor<double>::zero();
    state.plastic_strain = 0;
    return state;
  }
} // namespace

int main()
{
  const double E = 0.84e6, nu = 0.3;
  const double lambda = E * nu / ((1 + nu) * (1 - 2 * nu)), G = E / (2 * (1 + nu));

  MaterialParameters<double> elastic;
  elastic.model                  = MaterialModel::linear_elastic;
  elastic.elastic.youngs_modulus = E;
  elastic.elastic.poissons_ratio = nu;

  // Linear elastic, ratio 2: out to s = 3, back to s = 0.5.
  {
    MaterialParameters<double> m = elastic;
    m.disconnection_volume_ratio = 2;
    MaterialPointState<double> state = at_rest();
    std::vector<Step>          path  = drive(m, 1, 3, 400, state);
    const std::vector<Step>    back  = drive(m, 3, 0.5, 500, state);
    path.insert(path.end(), back.begin(), back.end());

    int    nonzero_beyond = 0;
    double sum_since      = 0, worst = 0, largest = 0;
    for (const Step &s : path)
      {
        if (s.J_new > 2)
          {
            nonzero_beyond += s.stress_xx != 0 || s.stress_yy != 0;
            sum_since = 0;
            continue;
          }
        sum_since += s.d_eps_xx;
        worst   = std::max({worst, std::abs(s.stress_xx - (lambda + 2 * G) * sum_since),
                            std::abs(s.stress_yy - lambda * sum_since)});
        largest = std::max(largest, std::abs(s.stress_xx));
      }
    std::printf("elastic, ratio 2: %d steps beyond J = 2 with a stress (0 expected); below it, stress against the "
                "increments since the crossing: %.3e of the largest %.4e Pa\n",
                nonzero_beyond, worst / largest, largest);
    mpm_test::check(nonzero_beyond == 0, "nonzero_beyond == 0");
    mpm_test::check(largest > 1e5, "largest > 1e5"); // the return to s = 0.5 compresses by about a factor 4 from the crossing
    mpm_test::check(worst <= 1e-12 * largest, "worst <= 1e-12 * largest");

    // The same path without the ratio: the sum over every increment.
    MaterialPointState<double> plain = at_rest();
    drive(elastic, 1, 3, 400, plain);
    drive(elastic, 3, 0.5, 500, plain);
    double all = 0;
    for (const Step &s : path)
      all += s.d_eps_xx;
    const double plain_error = std::abs(plain.stress[0] - (lambda + 2 * G) * all) / std::abs(plain.stress[0]);
    std::printf("elastic, ratio 0: sigma_xx %.6e against (lambda + 2G) sum d_eps %.6e (relative %.2e); with ratio 2 "
                "%.6e\n",
                plain.stress[0], (lambda + 2 * G) * all, plain_error, state.stress[0]);
    mpm_test::check(plain_error <= 1e-12, "plain_error <= 1e-12");
    mpm_test::check(std::abs(plain.stress[0] - state.stress[0]) > 0.1 * std::abs(plain.stress[0]), "std::abs(plain.stress[0] - state.stress[0]) > 0.1 * std::abs(plain.stress[0])");
  }

  // Drucker-Prager, c = 0, stretched to s = 3: plastic flow at the tension cut-off up to J = 2 only.
  {
    MaterialParameters<double> dp = elastic;
    dp.model                      = MaterialModel::drucker_prager;
    dp.drucker_prager.strength.cohesion        = 0;
    dp.drucker_prager.strength.friction_angle  = 19.8 * M_PI / 180;
    dp.drucker_prager.strength.dilatancy_angle = 0;
    dp.drucker_prager.strength.residual_friction_angle = dp.drucker_prager.strength.friction_angle;
    dp.drucker_prager.tensile_strength         = 0;
    MaterialParameters<double> with_ratio      = dp;
    with_ratio.disconnection_volume_ratio      = 2;

    MaterialPointState<double> a = at_rest(), b = at_rest();
    const std::vector<Step>    connected    = drive(dp, 1, 3, 400, a);
    const std::vector<Step>    disconnected = drive(with_ratio, 1, 3, 400, b);
    double grown_beyond = 0, at_two = 0;
    for (const Step &s : disconnected)
      if (s.J_new <= 2)
        at_two = s.plastic_strain;
      else
        grown_beyond = std::max(grown_beyond, std::abs(s.plastic_strain - at_two));
    std::printf("Drucker-Prager c = 0 stretched to J = 3: plastic strain %.6f without the ratio, %.6f with ratio 2 "
                "(%.6f at J = 2, growth beyond it %.1e)\n",
                a.plastic_strain, b.plastic_strain, at_two, grown_beyond);
    mpm_test::check(at_two > 0, "at_two > 0");
    mpm_test::check(grown_beyond == 0, "grown_beyond == 0");
    mpm_test::check(a.plastic_strain > 1.2 * b.plastic_strain, "a.plastic_strain > 1.2 * b.plastic_strain");
    mpm_test::check(b.stress[0] == 0 && b.stress[1] == 0 && b.stress[2] == 0, "b.stress[0] == 0 && b.stress[1] == 0 && b.stress[2] == 0");
  }
  return mpm_test::finish("test_disconnection");
}
