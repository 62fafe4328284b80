// Single-point drivers through the registered update_stress (Jaumann + trial + return):
// drained triaxial compression of one material point, axial strain driven, lateral stress
// held at -p0 by solving for the lateral strain increment each step (secant iterations to
// 1e-12 p0). Tension positive; q = sigma_lateral - sigma_axial > 0 in compression.
//  - elastic branch: q = E eps_axial (constant lateral stress), to 1e-9;
//  - peak (perfect plasticity): q_MC = (2 c cos phi + 2 p0 sin phi)/(1 - sin phi) on the MC
//    compression edge; DP inner fit q_DP = 6 (c cos phi + p0 sin phi)/(3 - sin phi); DP in
//    triaxial extension equals MC there (the inner fit touches MC on the extension meridian);
//  - dilatancy at the plateau: d eps_v / d eps_a = -2 sin psi / (1 - sin psi) (MC),
//    q_psi / (q_psi/3 - 1/sqrt(3)) (DP): the non-associated flow, by a second route;
//  - softening: q follows q(c(eps_p), phi(eps_p)); with the explicit softening the state after
//    each step is on the surface of the strength at the start-of-step eps_p (to 1e-9; the lag
//    behind the end-of-step strength, (dq/dc) H d_eps_p, is printed); q never rises after yield;
//    at the end q is the residual value to 1e-9;
//  - plane strain (6-component stress, eps_zz = 0): DP with psi = 0 tends to the plane-strain
//    limit q = 2 (k_phi + q_phi p0)/(1 - q_phi) (s_zz -> 0) and MC to its plane-return value.
#include <mpm/core/material/material.h>

#include "check.h"

#include <cstdio>
#include <initializer_list>

using namespace mpm;
using mpm_test::check;
using mpm_test::check_below;

namespace
{
  constexpr double deg = 3.14159265358979323846 / 180;

  struct Driver
  {
    MaterialParameters<double> m;
    MaterialPointState<double> state;
    double                     p0;
    bool                       plane_strain = false; // z is the out-of-plane direction, eps_zz = 0
    double                     eps_axial = 0, eps_vol = 0;

    // axial direction: z (triaxial) or y (plane strain); lateral held at -p0: x and y (triaxial), x (plane)
    void start(const double confinement)
    {
      p0 = confinement;
      for (int i = 0; i < 6; ++i)
        state.stress[i] = i < 3 ? -p0 : 0;
      state.plastic_strain = 0;
    }

    MaterialPointState<double> trial(const double d_axial, const double d_lateral) const
    {
      SymTensor<double> d_eps = SymTensor<double>::zero();
      if (plane_strain)
        d_eps[0] = d_lateral, d_eps[1] = d_axial;
      else
        d_eps[0] = d_eps[1] = d_lateral, d_eps[2] = d_axial;
      MaterialPointState<double> s = state;
      update_stress(m, d_eps, Mat3<double>::zero(), s);
      return s;
    }

    // one axial strain increment; returns the eps_p at the start of the increment
    double step(const double d_axial)
    {
      const double K = m.elastic.bulk_modulus(), G = m.elastic.shear_modulus(), lambda = K - 2 * G / 3;
      auto residual = [&](const double e) { return trial(d_axial, e).stress[0] + p0; };
      double e0 = -lambda / (2 * (lambda + G)) * d_axial, r0 = residual(e0);
      double e1 = e0 - r0 / (2 * (lambda + G)), r1 = residual(e1);
      for (int it = 0; it < 100 && std::abs(r1) > 1e-13 * p0; ++it)
        {
          const double e2 = r1 == r0 ? e1 : e1 - r1 * (e1 - e0) / (r1 - r0);
          e0 = e1, r0 = r1, e1 = e2, r1 = residual(e1);
        }
      check(std::abs(r1) <= 1e-12 * p0, "driver: lateral stress held", r1, 1e-12 * p0);
      const double eps_p0 = state.plastic_strain;
      state               = trial(d_axial, e1);
      eps_axial += d_axial;
      eps_vol += d_axial + (plane_strain ? 1 : 2) * e1;
      return eps_p0;
    }

    double axial_stress() const { return state.stress[plane_strain ? 1 : 2]; }
    double q() const { return -p0 - axial_stress(); } // lateral minus axial (compression positive)
  };

  double q_mc(const double c, const double phi, const double p0) // triaxial compression, MC
  {
    return (2 * c * std::cos(phi) + 2 * p0 * std::sin(phi)) / (1 - std::sin(phi));
  }
  double q_dp(const double c, const double phi, const double p0) // triaxial compression, DP inner fit
  {
    return 6 * (c * std::cos(phi) + p0 * std::sin(phi)) / (3 - std::sin(phi));
  }
  double q_ext(const double c, const double phi, const double p0) // triaxial extension, MC and DP inner fit
  {
    return 2 * (c * std::cos(phi) + p0 * std::sin(phi)) / (1 + std::sin(phi));
  }
  double q_psi_of(const double psi)
  {
    return 6 * std::sin(psi) / (std::sqrt(3.0) * (3 + std::sin(psi)));
  }

  MaterialParameters<double> material(const MaterialModel model, const double c, const double phi, const double psi)
  {
    MaterialParameters<double> m;
    m.model   = model;
    m.elastic = {2e7, 0.3};
    SofteningStrength<double> s;
    s.cohesion = s.residual_cohesion = c;
    s.friction_angle = s.residual_friction_angle = phi;
    s.dilatancy_angle                            = psi;
    m.drucker_prager.strength                    = s;
    m.mohr_coulomb.strength                      = s;
    return m;
  }

  // Perfect plasticity: elastic slope, peak, plateau dilatancy.
  void peak_and_dilatancy(const MaterialModel model, const double c, const double phi, const double psi,
                          const double p0)
  {
    const bool mc = model == MaterialModel::mohr_coulomb;
    Driver     d;
    d.m = material(model, c, phi, psi);
    d.start(p0);
    const double q_ref = mc ? q_mc(c, phi, p0) : q_dp(c, phi, p0);
    const double E     = d.m.elastic.youngs_modulus;
    const double de    = -q_ref / E / 1000; // peak after ~1000 increments
    double       worst_elastic = 0, q_max = 0, dv = 0, da = 0;
    for (int n = 0; n < 6000; ++n)
      {
        const double v0 = d.eps_vol, a0 = d.eps_axial;
        d.step(de);
        q_max = std::max(q_max, d.q());
        if (d.state.plastic_strain == 0)
          worst_elastic = std::max(worst_elastic, std::abs(d.q() - E * -d.eps_axial) / q_ref);
        if (n >= 3000) // well past the peak: stress constant, all strain plastic
          dv += d.eps_vol - v0, da += d.eps_axial - a0;
      }
    const double ratio_ref = mc ? -2 * std::sin(psi) / (1 - std::sin(psi))
                                : q_psi_of(psi) / (q_psi_of(psi) / 3 - 1 / std::sqrt(3.0));
    std::printf("%s c %5.0f phi %4.1f psi %4.1f p0 %6.0f: q_peak %.6e (analytic %.6e, rel %.1e), "
                "elastic rel %.1e, dilatancy %.6f (analytic %.6f)\n",
                mc ? "MC" : "DP", c, phi / deg, psi / deg, p0, q_max, q_ref, std::abs(q_max - q_ref) / q_ref,
                worst_elastic, dv / da, ratio_ref);
    check_below(worst_elastic, 1e-9, "triaxial: elastic branch q = E eps_a");
    check_below(std::abs(q_max - q_ref) / q_ref, 1e-9, "triaxial: peak deviatoric stress = analytic");
    check_below(std::abs(dv / da - ratio_ref), 1e-8, "triaxial: plateau dilatancy ratio from psi");
    check(d.eps_axial < -5 * q_ref / E, "triaxial: driven well past the peak");
  }

  // Triaxial extension: axial stress rises above -p0; DP inner fit and MC give the same limit.
  void extension(const MaterialModel model)
  {
    const double c = 1e4, phi = 30 * deg, p0 = 1e5;
    Driver       d;
    d.m = material(model, c, phi, 0);
    d.start(p0);
    for (int n = 0; n < 3000; ++n)
      d.step(+2e-6);
    const double q_ref = q_ext(c, phi, p0), q = -d.q();
    std::printf("%s extension: q %.6e analytic %.6e rel %.1e\n", model == MaterialModel::mohr_coulomb ? "MC" : "DP",
                q, q_ref, std::abs(q - q_ref) / q_ref);
    check_below(std::abs(q - q_ref) / q_ref, 1e-9, "triaxial extension limit (DP inner fit = MC)");
  }

  // Cohesion (and optionally friction) softening.
  void softening(const MaterialModel model, const bool friction_softening)
  {
    const bool   mc = model == MaterialModel::mohr_coulomb;
    const double p0 = 5e4, c_peak = 2e4, c_res = 5e3, H = 1e6, phi_peak = 30 * deg;
    const double phi_res = friction_softening ? 20 * deg : phi_peak, psi = 5 * deg;
    Driver       d;
    d.m                      = material(model, c_peak, phi_peak, psi);
    SofteningStrength<double> &s = mc ? d.m.mohr_coulomb.strength : d.m.drucker_prager.strength;
    s.residual_cohesion          = c_res;
    s.softening_modulus          = H;
    s.residual_friction_angle    = phi_res;
    d.start(p0);
    auto q_of = [&](const double eps_p) {
      const double c = softened_cohesion(s, eps_p), phi = softened_friction_angle(s, eps_p);
      return mc ? q_mc(c, phi, p0) : q_dp(c, phi, p0);
    };
    const double eps_res = (c_peak - c_res) / H;
    double worst_start = 0, worst_lag = 0, max_dep = 0;
    bool   monotone = true;
    double q_prev = 0, eps_p_prev = 0;
    for (int n = 0; n < 20000; ++n)
      {
        const double eps_p0 = d.step(-5e-6);
        const double eps_p1 = d.state.plastic_strain;
        if (eps_p1 > 0)
          {
            const double q = d.q();
            worst_start    = std::max(worst_start, std::abs(q - q_of(eps_p0)) / q_of(0));
            // lag behind the end-of-step strength (explicit softening), for information
            worst_lag = std::max(worst_lag, std::abs(q - q_of(eps_p1)) / q_of(0));
            max_dep          = std::max(max_dep, eps_p1 - eps_p0);
            if (eps_p_prev > 0 && q > q_prev * (1 + 1e-12))
              monotone = false;
            q_prev = q, eps_p_prev = eps_p1;
          }
      }
    const double q_end = d.q(), q_res = q_of(1.0);
    std::printf("%s softening%s: eps_p end %.4f (residual from %.4f), q end %.6e residual analytic %.6e rel %.1e; "
                "on surface of start-of-step strength %.1e; lag behind end-of-step strength %.1e (max d eps_p %.1e)\n",
                mc ? "MC" : "DP", friction_softening ? " (c and phi)" : " (c)", d.state.plastic_strain, eps_res,
                q_end, q_res, std::abs(q_end - q_res) / q_res, worst_start, worst_lag, max_dep);
    check(d.state.plastic_strain > 2 * eps_res, "softening: driven past the residual strain");
    check_below(worst_start, 1e-9, "softening: q = q(c(eps_p), phi(eps_p)) at the start-of-step eps_p");
    check_below(std::abs(q_end - q_res) / q_res, 1e-9, "softening: residual strength reached");
    check(monotone, "softening: q never rises after yield");
  }

  // Plane strain through the 6-component stress.
  void plane_strain(const MaterialModel model)
  {
    const double c = 1e4, phi = 30 * deg, p0 = 1e5;
    Driver       d;
    d.m            = material(model, c, phi, 0);
    d.plane_strain = true;
    d.start(p0);
    for (int n = 0; n < 60000; ++n)
      d.step(-5e-6);
    const DruckerPragerCoefficients<double> k =
      drucker_prager_coefficients(current_strength(d.m.drucker_prager.strength, 0.0), 1e30);
    const bool   mc    = model == MaterialModel::mohr_coulomb;
    const double q_ref = mc ? q_mc(c, phi, p0) : 2 * (k.k_phi + k.q_phi * p0) / (1 - k.q_phi);
    const double szz   = d.state.stress[2] - mean_stress(d.state.stress);
    std::printf("%s plane strain: q %.6e analytic %.6e rel %.1e, sigma_zz %.4e (s_zz %.1e)\n", mc ? "MC" : "DP",
                d.q(), q_ref, std::abs(d.q() - q_ref) / q_ref, d.state.stress[2], szz);
    check_below(std::abs(d.q() - q_ref) / q_ref, 1e-6, "plane strain: limit deviatoric stress");
    check(d.state.stress[2] < -p0 && d.state.stress[2] > d.axial_stress(), "plane strain: sigma_zz intermediate");
  }
} // namespace

int main()
{
  for (const MaterialModel model : {MaterialModel::mohr_coulomb, MaterialModel::drucker_prager})
    {
      peak_and_dilatancy(model, 2e4, 30 * deg, 0, 1e5);
      peak_and_dilatancy(model, 2e4, 30 * deg, 30 * deg, 1e5);
      peak_and_dilatancy(model, 0, 19.8 * deg, 0, 5e3);
      peak_and_dilatancy(model, 1e4, 40 * deg, 10 * deg, 3e5);
      extension(model);
      softening(model, false);
      softening(model, true);
      plane_strain(model);
    }
  return mpm_test::finish("test_triaxial");
}
