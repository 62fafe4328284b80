// Return-mapping tests for Drucker-Prager (tension cut-off) and Mohr-Coulomb, over
// thousands of random trial stresses per parameter set:
//  - the Jacobi eigen-solver: residual, orthonormality, repeated eigenvalues;
//  - returned stress on or inside every yield surface, |f| < 1e-10 relative on the active ones;
//  - flow direction from the potential, checked mode-agnostically: the plastic strain
//    C^-1 (sigma_trial - sigma) must lie in the normal cone of the active potentials at the
//    returned stress, with non-negative multipliers (non-associated: g, not f);
//  - elastic trial states returned bit-for-bit untouched, plasticity_enabled = false is elastic;
//  - associated flow (psi = phi): the result equals the closest point in the energy norm,
//    computed here independently in closed form (DP: 2D projection onto the meridian polygon;
//    MC: projection onto every face, edge and the apex of the 6-plane cone, nearest admissible);
//  - every return mode is exercised (counts asserted), so the checks cannot pass vacuously.
// Tolerances: 1e-10 relative to |sigma_trial| + c for stresses (the return is a few dozen
// flops from the trial, round-off ~1e-15, the eigen-solver ~1e-15): 1e-10 leaves 5 orders.
#include <mpm/core/material/material.h>

#include "check.h"

#include <algorithm>
#include <cstdio>
#include <random>

using namespace mpm;
using mpm_test::check;
using mpm_test::check_below;

namespace
{
  constexpr double pi  = 3.14159265358979323846;
  constexpr double deg = pi / 180;

  double norm(const SymTensor<double> &t)
  {
    double s = 0;
    for (int i = 0; i < 6; ++i)
      s += (i < 3 ? 1 : 2) * t[i] * t[i];
    return std::sqrt(s);
  }

  SymTensor<double> minus(const SymTensor<double> &a, const SymTensor<double> &b)
  {
    SymTensor<double> r;
    for (int i = 0; i < 6; ++i)
      r[i] = a[i] - b[i];
    return r;
  }

  // C^-1 sigma: s/(2G) + p/(3K) I
  SymTensor<double> compliance(const LinearElasticParameters<double> &e, const SymTensor<double> &s)
  {
    const double p = mean_stress(s), G = e.shear_modulus(), K = e.bulk_modulus();
    SymTensor<double> r;
    for (int i = 0; i < 3; ++i)
      r[i] = (s[i] - p) / (2 * G) + p / (3 * K);
    for (int i = 3; i < 6; ++i)
      r[i] = s[i] / (2 * G);
    return r;
  }

  Mat3<double> random_rotation(std::mt19937 &rng)
  {
    std::normal_distribution<double> n(0, 1);
    double q[4], s = 0;
    for (double &c : q)
      c = n(rng), s += c * c;
    s = std::sqrt(s);
    for (double &c : q)
      c /= s;
    const double w = q[0], x = q[1], y = q[2], z = q[3];
    Mat3<double> R;
    R.a[0][0] = 1 - 2 * (y * y + z * z), R.a[0][1] = 2 * (x * y - z * w), R.a[0][2] = 2 * (x * z + y * w);
    R.a[1][0] = 2 * (x * y + z * w), R.a[1][1] = 1 - 2 * (x * x + z * z), R.a[1][2] = 2 * (y * z - x * w);
    R.a[2][0] = 2 * (x * z - y * w), R.a[2][1] = 2 * (y * z + x * w), R.a[2][2] = 1 - 2 * (x * x + y * y);
    return R;
  }

  // Random trial stress of magnitude ~S: random principal values (sometimes repeated, sometimes
  // hydrostatic), random orientation, mean stress from deep compression to beyond the apex.
  SymTensor<double> random_trial(std::mt19937 &rng, const double S)
  {
    std::uniform_real_distribution<double> u(0, 1);
    double       l[3];
    const double p = S * (-4 + 5 * u(rng));
    for (double &v : l)
      v = p + S * (2 * u(rng) - 1) * (u(rng) < 0.2 ? 0.05 : 1.5);
    const double kind = u(rng);
    if (kind < 0.1)
      l[1] = l[0];
    else if (kind < 0.2)
      l[2] = l[1];
    else if (kind < 0.25)
      l[0] = l[1] = l[2];
    Mat3<double> V = kind < 0.35 ? Mat3<double>::identity() : random_rotation(rng);
    return from_principal(l, V);
  }

  // ------------------------------------------------------------------ eigen-solver
  void test_eigen()
  {
    std::mt19937 rng(1);
    double       worst_residual = 0, worst_orth = 0;
    for (int trial = 0; trial < 20000; ++trial)
      {
        const SymTensor<double> t = random_trial(rng, 1e5);
        double                  l[3];
        Mat3<double>            V;
        symmetric_eigen(t, l, V);
        const double scale = norm(t) + 1e-300;
        check(l[0] >= l[1] && l[1] >= l[2], "eigenvalues sorted");
        for (int k = 0; k < 3; ++k)
          for (int i = 0; i < 3; ++i)
            {
              double r = -l[k] * V.a[i][k];
              for (int j = 0; j < 3; ++j)
                r += t(i, j) * V.a[j][k];
              worst_residual = std::max(worst_residual, std::abs(r) / scale);
            }
        const Mat3<double> VtV = multiply(transpose(V), V);
        for (int i = 0; i < 3; ++i)
          for (int j = 0; j < 3; ++j)
            worst_orth = std::max(worst_orth, std::abs(VtV.a[i][j] - (i == j)));
      }
    std::printf("eigen: worst residual %.2e, worst orthonormality %.2e\n", worst_residual, worst_orth);
    check_below(worst_residual, 1e-14, "eigen residual |A v - l v| / |A|");
    check_below(worst_orth, 1e-14, "eigenvectors orthonormal");
  }

  // ------------------------------------------------------------------ Drucker-Prager
  struct DPCase
  {
    double phi, psi, c, sigma_t, nu;
  };

  // Closest point (energy norm) of (p, tau) on the DP-with-cut-off meridian polygon, in the
  // scaled plane u = p / sqrt(K), v = tau / sqrt(G) where the energy norm is Euclidean.
  void dp_closest_point(const DruckerPragerCoefficients<double> &k, const double K, const double G,
                        const double p, const double tau, double &p_out, double &tau_out)
  {
    const double sK = std::sqrt(K), sG = std::sqrt(G);
    const double U = p / sK, V = tau / sG;
    const double uc = k.sigma_t / sK, vc = k.tau_P / sG; // corner
    double best = 1e300;
    auto consider = [&](const double u, const double v) {
      const double d = (u - U) * (u - U) + (v - V) * (v - V);
      if (d < best)
        best = d, p_out = u * sK, tau_out = v * sG;
    };
    // tension edge: u = uc, v in [0, vc]
    consider(uc, std::clamp(V, 0.0, vc));
    // shear edge sqrt(G) v + q sqrt(K) u = k_phi: from the corner along (-sqrt(G), q sqrt(K)), p falling
    const double du = -sG, dv = k.q_phi * sK, len = std::sqrt(du * du + dv * dv);
    const double t = std::max(0.0, ((U - uc) * du + (V - vc) * dv) / len);
    consider(uc + t * du / len, vc + t * dv / len);
  }

  void test_drucker_prager(const DPCase &pc, std::mt19937 &rng, const int n, int mode_count[4])
  {
    LinearElasticParameters<double> el{2e7, pc.nu};
    CurrentStrength<double>         s{pc.c, std::sin(pc.phi), std::cos(pc.phi), std::sin(pc.psi)};
    const DruckerPragerCoefficients<double> k = drucker_prager_coefficients(s, pc.sigma_t);
    const double K = el.bulk_modulus(), G = el.shear_modulus();
    const bool   associated = pc.psi == pc.phi;
    const double S = 1e5;
    double worst_f = 0, worst_surface = 0, worst_flow = 0, worst_mult = 0, worst_closed = 0, worst_report = 0;
    int    n_elastic_changed = 0;
    for (int trial = 0; trial < n; ++trial)
      {
        const SymTensor<double> tr = random_trial(rng, S);
        SymTensor<double>       st = tr;
        const ReturnResult<double> r = drucker_prager_return(el, k, st);
        const double scale = norm(tr) + pc.c;
        const double tol   = 1e-10 * scale;
        auto f_s = [&](const SymTensor<double> &x) {
          return std::sqrt(second_deviatoric_invariant(x)) + k.q_phi * mean_stress(x) - k.k_phi;
        };
        auto f_t = [&](const SymTensor<double> &x) { return mean_stress(x) - k.sigma_t; };
        const double fs_tr = f_s(tr), ft_tr = f_t(tr);
        if (fs_tr < -1e-12 * scale && ft_tr < -1e-12 * scale)
          {
            bool same = r.mode == ReturnMode::elastic;
            for (int i = 0; i < 6; ++i)
              same = same && st[i] == tr[i];
            n_elastic_changed += !same;
            ++mode_count[0];
            continue;
          }
        if (fs_tr <= 1e-12 * scale && ft_tr <= 1e-12 * scale)
          continue; // on the surface to round-off: either answer is right
        ++mode_count[int(r.mode)];
        const double fs = f_s(st), ft = f_t(st);
        worst_f = std::max({worst_f, fs / scale, ft / scale});
        // on the surface: the larger of the two is zero
        worst_surface = std::max(worst_surface, std::abs(std::max(fs, ft)) / scale);

        // flow: d_eps^p = mu_s (s/(2 tau) + q_psi I/3) + mu_t I/3
        const SymTensor<double> dep = compliance(el, minus(tr, st));
        const double            ev  = trace(dep);
        SymTensor<double>       de  = dep, s_new = st;
        for (int i = 0; i < 3; ++i)
          de[i] -= ev / 3, s_new[i] -= mean_stress(st);
        const double tau_new = std::sqrt(second_deviatoric_invariant(st));
        const double mu_s    = std::sqrt(2.0) * norm(de);
        const double mu_t    = ev - k.q_psi * mu_s;
        const double mscale  = norm(compliance(el, tr)) + pc.c / G;
        if (tau_new > tol)
          {
            SymTensor<double> dir = s_new;
            for (int i = 0; i < 6; ++i)
              dir[i] *= mu_s / (2 * tau_new);
            worst_flow = std::max(worst_flow, norm(minus(de, dir)) / mscale);
          }
        worst_mult = std::max(worst_mult, -mu_t / mscale); // mu_t >= 0
        if (fs < -tol)
          worst_mult = std::max(worst_mult, mu_s / mscale); // shear inactive: mu_s = 0
        if (ft < -tol)
          worst_mult = std::max(worst_mult, std::abs(mu_t) / mscale); // tension inactive: mu_t = 0
        worst_report = std::max({worst_report, std::abs(r.multiplier[0] - mu_s) / mscale,
                                 std::abs(r.multiplier[1] - mu_t) / mscale,
                                 std::abs(r.d_plastic_strain - std::sqrt(2.0 / 3.0) * norm(dep)) / mscale});
        if (associated)
          {
            double p_ref, tau_ref;
            dp_closest_point(k, K, G, mean_stress(tr), std::sqrt(second_deviatoric_invariant(tr)), p_ref, tau_ref);
            worst_closed = std::max({worst_closed, std::abs(mean_stress(st) - p_ref) / scale,
                                     std::abs(tau_new - tau_ref) / scale});
          }
      }
    std::printf("DP phi %4.1f psi %4.1f c %6.0f sigma_t %7.0f nu %.2f: f+ %.1e |f| %.1e flow %.1e "
                "mult %.1e reported %.1e closed-form %.1e\n",
                pc.phi / deg, pc.psi / deg, pc.c, std::min(pc.sigma_t, 1e9), pc.nu, worst_f, worst_surface,
                worst_flow, worst_mult, worst_report, worst_closed);
    check(n_elastic_changed == 0, "DP: elastic trial states untouched", n_elastic_changed);
    check_below(worst_f, 1e-10, "DP: returned stress inside f_s <= 0 and f_t <= 0");
    check_below(worst_surface, 1e-10, "DP: returned stress on the yield surface");
    check_below(worst_flow, 1e-10, "DP: deviatoric plastic strain parallel to s (potential g_s)");
    check_below(worst_mult, 1e-10, "DP: multipliers non-negative, zero on inactive surfaces");
    check_below(worst_report, 1e-10, "DP: reported multipliers and eps_p increment");
    check_below(worst_closed, 1e-10, "DP associated: closest point in the energy norm");
  }

  // ------------------------------------------------------------------ Mohr-Coulomb
  struct MCCase
  {
    double phi, psi, c, nu;
  };

  // Independent closed form for associated flow: the closest admissible point in the energy
  // norm among the projections onto every plane, every pair of planes and the apex of the
  // 6-plane cone (unsorted principal space; C = lambda 11^T + 2G I).
  void mc_closest_point(const LinearElasticParameters<double> &el, const CurrentStrength<double> &s,
                        const double tr[3], double out[3])
  {
    const double K = el.bulk_modulus(), G = el.shear_modulus(), lambda = K - 2 * G / 3;
    const double sf = s.sin_phi, r = 2 * s.cohesion * s.cos_phi;
    double a[6][3];
    int    n = 0;
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j)
        if (i != j)
          {
            a[n][0] = a[n][1] = a[n][2] = 0;
            a[n][i] += 1 + sf, a[n][j] -= 1 - sf;
            ++n;
          }
    auto Cv = [&](const double v[3], double o[3]) {
      for (int i = 0; i < 3; ++i)
        o[i] = lambda * (v[0] + v[1] + v[2]) + 2 * G * v[i];
    };
    auto energy = [&](const double d[3]) {
      const double p = (d[0] + d[1] + d[2]) / 3;
      double       e = 0;
      for (int i = 0; i < 3; ++i)
        e += d[i] * ((d[i] - p) / (2 * G) + p / (3 * K));
      return e;
    };
    auto admissible = [&](const double x[3]) {
      const double scale = std::abs(tr[0]) + std::abs(tr[1]) + std::abs(tr[2]) + s.cohesion;
      for (int m = 0; m < 6; ++m)
        if (a[m][0] * x[0] + a[m][1] * x[1] + a[m][2] * x[2] - r > 1e-12 * scale)
          return false;
      return true;
    };
    double best = 1e300;
    auto consider = [&](const double x[3]) {
      const double d[3] = {tr[0] - x[0], tr[1] - x[1], tr[2] - x[2]};
      const double e    = energy(d);
      if (admissible(x) && e < best)
        best = e, out[0] = x[0], out[1] = x[1], out[2] = x[2];
    };
    for (int m = 0; m < 6; ++m)
      {
        double Ca[3];
        Cv(a[m], Ca);
        const double g = a[m][0] * tr[0] + a[m][1] * tr[1] + a[m][2] * tr[2] - r;
        const double dl = g / (a[m][0] * Ca[0] + a[m][1] * Ca[1] + a[m][2] * Ca[2]);
        const double x[3] = {tr[0] - dl * Ca[0], tr[1] - dl * Ca[1], tr[2] - dl * Ca[2]};
        consider(x);
        for (int q = m + 1; q < 6; ++q)
          {
            double Cb[3];
            Cv(a[q], Cb);
            const double m11 = a[m][0] * Ca[0] + a[m][1] * Ca[1] + a[m][2] * Ca[2];
            const double m12 = a[m][0] * Cb[0] + a[m][1] * Cb[1] + a[m][2] * Cb[2];
            const double m22 = a[q][0] * Cb[0] + a[q][1] * Cb[1] + a[q][2] * Cb[2];
            const double det = m11 * m22 - m12 * m12;
            if (std::abs(det) < 1e-12 * m11 * m22)
              continue; // parallel planes
            const double g2 = a[q][0] * tr[0] + a[q][1] * tr[1] + a[q][2] * tr[2] - r;
            const double l1 = (g * m22 - m12 * g2) / det, l2 = (m11 * g2 - m12 * g) / det;
            const double y[3] = {tr[0] - l1 * Ca[0] - l2 * Cb[0], tr[1] - l1 * Ca[1] - l2 * Cb[1],
                                 tr[2] - l1 * Ca[2] - l2 * Cb[2]};
            consider(y);
          }
      }
    if (sf > 0)
      {
        const double ap = s.cohesion * s.cos_phi / sf, x[3] = {ap, ap, ap};
        consider(x);
      }
  }

  void test_mohr_coulomb(const MCCase &pc, std::mt19937 &rng, const int n, int mode_count[7])
  {
    LinearElasticParameters<double> el{2e7, pc.nu};
    CurrentStrength<double>         s{pc.c, std::sin(pc.phi), std::cos(pc.phi), std::sin(pc.psi)};
    const double sp = s.sin_psi, G = el.shear_modulus();
    const double m  = (1 + sp) / (1 - sp);
    const bool   associated = pc.psi == pc.phi;
    const double S = 1e5;
    double worst_f = 0, worst_surface = 0, worst_coaxial = 0, worst_flow = 0, worst_mult = 0, worst_closed = 0,
           worst_report = 0, worst_apex = 0;
    int n_elastic_changed = 0;
    for (int trial = 0; trial < n; ++trial)
      {
        const SymTensor<double> tr = random_trial(rng, S);
        SymTensor<double>       st = tr;
        const ReturnResult<double> r = mohr_coulomb_return(el, s, st);
        const double scale = norm(tr) + pc.c;
        const double tol   = 1e-10 * scale;
        double       l_tr[3], l[3];
        Mat3<double> V, W;
        symmetric_eigen(tr, l_tr, V);
        const double f_tr = mohr_coulomb_yield(s, l_tr);
        if (f_tr < -1e-12 * scale)
          {
            bool same = r.mode == ReturnMode::elastic;
            for (int i = 0; i < 6; ++i)
              same = same && st[i] == tr[i];
            n_elastic_changed += !same;
            ++mode_count[0];
            continue;
          }
        if (f_tr <= 1e-12 * scale)
          continue;
        ++mode_count[int(r.mode)];
        symmetric_eigen(st, l, W);
        const double f = mohr_coulomb_yield(s, l);
        worst_f       = std::max(worst_f, f / scale);
        worst_surface = std::max(worst_surface, std::abs(f) / scale);
        // coaxiality: sigma and sigma_trial commute
        const Mat3<double> A = to_matrix(st), B = to_matrix(tr), AB = multiply(A, B), BA = multiply(B, A);
        for (int i = 0; i < 3; ++i)
          for (int j = 0; j < 3; ++j)
            worst_coaxial = std::max(worst_coaxial, std::abs(AB.a[i][j] - BA.a[i][j]) / (scale * scale));

        // plastic strain and returned stress in the trial's principal frame
        const SymTensor<double> dep = compliance(el, minus(tr, st));
        const Mat3<double>      D = multiply(multiply(transpose(V), to_matrix(dep)), V);
        const Mat3<double>      Sg = multiply(multiply(transpose(V), A), V);
        const double x[3] = {D.a[0][0], D.a[1][1], D.a[2][2]}, sn[3] = {Sg.a[0][0], Sg.a[1][1], Sg.a[2][2]};
        const double mscale = norm(compliance(el, tr)) + pc.c / G;
        const double flow_tol = 1e-10 * mscale;
        const bool   eq01 = sn[0] - sn[1] <= tol, eq12 = sn[1] - sn[2] <= tol;
        double       mu1 = 0, mu2 = 0, resid = 0;
        if (eq01 && eq12)
          {
            // apex: sigma = c cot(phi) 1
            const double ap = pc.c * s.cos_phi / s.sin_phi;
            for (int i = 0; i < 3; ++i)
              worst_apex = std::max(worst_apex, std::abs(sn[i] - ap) / scale);
            check(r.mode == ReturnMode::apex, "MC: equal principal stresses only at the apex");
            check(x[0] + x[1] + x[2] > 0, "MC apex: dilative plastic strain (trial beyond the apex)");
            // normal cone of g at the apex (psi > 0): x in cone{perm(m, 0, -1)} iff, sorted y,
            // y0 + m (y1 + y2) >= 0 and y0 + y1 + m y2 >= 0. For psi = 0 the cone is the
            // deviatoric plane and has no volumetric part: no consistent apex return exists.
            if (sp > 0)
              {
                double y[3] = {x[0], x[1], x[2]};
                std::sort(y, y + 3, [](double a, double b) { return a > b; });
                mu1 = y[0] + m * (y[1] + y[2]), mu2 = y[0] + y[1] + m * y[2];
              }
            else
              mu1 = mu2 = 0;
          }
        else if (eq01)
          {
            // sigma_1 = sigma_2: planes (1,3) and (2,3), x = mu1 (1+sp, 0, -(1-sp)) + mu2 (0, 1+sp, -(1-sp))
            mu1 = x[0] / (1 + sp), mu2 = x[1] / (1 + sp);
            resid = std::abs(x[2] + (1 - sp) * (mu1 + mu2));
            check(r.mode == ReturnMode::edge_compression, "MC: sigma_1 = sigma_2 reported as compression edge");
          }
        else if (eq12)
          {
            // sigma_2 = sigma_3: planes (1,3) and (1,2), x = mu1 (1+sp, 0, -(1-sp)) + mu2 (1+sp, -(1-sp), 0)
            mu1 = -x[2] / (1 - sp), mu2 = -x[1] / (1 - sp);
            resid = std::abs(x[0] - (1 + sp) * (mu1 + mu2));
            check(r.mode == ReturnMode::edge_extension, "MC: sigma_2 = sigma_3 reported as extension edge");
          }
        else
          {
            mu1   = x[0] / (1 + sp);
            resid = std::abs(x[1]) + std::abs(x[2] + (1 - sp) * mu1);
            check(r.mode == ReturnMode::shear, "MC: distinct principal stresses reported as plane return");
          }
        for (int i = 0; i < 3; ++i)
          for (int j = 0; j < 3; ++j)
            if (i != j)
              resid += std::abs(D.a[i][j]); // plastic strain coaxial with the stress
        worst_flow = std::max(worst_flow, resid / mscale);
        worst_mult = std::max({worst_mult, -mu1 / mscale, -mu2 / mscale});
        (void)flow_tol;
        worst_report = std::max(worst_report, std::abs(r.d_plastic_strain - std::sqrt(2.0 / 3.0) * norm(dep)) / mscale);
        if (associated)
          {
            double ref[3];
            mc_closest_point(el, s, l_tr, ref);
            std::sort(ref, ref + 3, [](double a, double b) { return a > b; });
            for (int i = 0; i < 3; ++i)
              worst_closed = std::max(worst_closed, std::abs(ref[i] - l[i]) / scale);
          }
      }
    std::printf("MC phi %4.1f psi %4.1f c %6.0f nu %.2f: f+ %.1e |f| %.1e coaxial %.1e flow %.1e mult %.1e "
                "apex %.1e reported %.1e closed-form %.1e\n",
                pc.phi / deg, pc.psi / deg, pc.c, pc.nu, worst_f, worst_surface, worst_coaxial, worst_flow,
                worst_mult, worst_apex, worst_report, worst_closed);
    check(n_elastic_changed == 0, "MC: elastic trial states untouched", n_elastic_changed);
    check_below(worst_f, 1e-10, "MC: returned stress inside f <= 0");
    check_below(worst_surface, 1e-10, "MC: returned stress on the yield surface");
    check_below(worst_coaxial, 1e-12, "MC: returned stress coaxial with the trial");
    check_below(worst_flow, 1e-10, "MC: plastic strain along the potential's gradients");
    check_below(worst_mult, 1e-10, "MC: multipliers non-negative (apex: in the cone of g)");
    check_below(worst_apex, 1e-10, "MC: apex stress c cot(phi)");
    check_below(worst_report, 1e-10, "MC: reported eps_p increment");
    check_below(worst_closed, 1e-10, "MC associated: closest point in the energy norm");
  }

  // plasticity_enabled = false: identical to linear elasticity, bit for bit; and the DP and MC
  // updates apply the Jaumann rotation before the trial (elastic states agree with linear_elastic).
  void test_switch_and_elastic_path()
  {
    std::mt19937                           rng(5);
    std::uniform_real_distribution<double> u(-1, 1);
    MaterialParameters<double>             lin, dp, mc;
    lin.model = MaterialModel::linear_elastic;
    dp.model  = MaterialModel::drucker_prager;
    mc.model  = MaterialModel::mohr_coulomb;
    for (MaterialParameters<double> *m : {&lin, &dp, &mc})
      m->elastic = {1e7, 0.3};
    dp.drucker_prager.strength.cohesion       = 1e3;
    dp.drucker_prager.strength.friction_angle = 30 * deg;
    mc.mohr_coulomb.strength                  = dp.drucker_prager.strength;
    int n_diff_off = 0, n_plastic_on = 0, n_diff_elastic = 0, n_elastic = 0;
    for (int trial = 0; trial < 2000; ++trial)
      {
        MaterialPointState<double> s0;
        for (int i = 0; i < 6; ++i)
          s0.stress[i] = 1e4 * u(rng) - (i < 3 ? 2e4 : 0);
        s0.plastic_strain = 0.01;
        SymTensor<double> d_eps;
        for (int i = 0; i < 6; ++i)
          d_eps[i] = 1e-3 * u(rng);
        Mat3<double> dW = Mat3<double>::zero();
        dW.a[0][1] = 0.1 * u(rng), dW.a[1][2] = 0.1 * u(rng), dW.a[0][2] = 0.1 * u(rng);
        for (int i = 0; i < 3; ++i)
          for (int j = 0; j < i; ++j)
            dW.a[i][j] = -dW.a[j][i];
        MaterialPointState<double> a = s0;
        update_stress(lin, d_eps, dW, a);
        for (MaterialParameters<double> *m : {&dp, &mc})
          {
            m->plasticity_enabled        = false;
            MaterialPointState<double> b = s0;
            update_stress(*m, d_eps, dW, b);
            for (int i = 0; i < 6; ++i)
              n_diff_off += b.stress[i] != a.stress[i];
            n_diff_off += b.plastic_strain != s0.plastic_strain;
            m->plasticity_enabled = true;
            b                     = s0;
            update_stress(*m, d_eps, dW, b);
            if (b.plastic_strain == s0.plastic_strain)
              {
                ++n_elastic;
                for (int i = 0; i < 6; ++i)
                  n_diff_elastic += b.stress[i] != a.stress[i];
              }
            else
              ++n_plastic_on;
          }
      }
    std::printf("switch: %d differences with plasticity off; %d elastic, %d plastic updates with it on\n",
                n_diff_off, n_elastic, n_plastic_on);
    check(n_diff_off == 0, "plasticity_enabled = false gives linear elasticity bit for bit", n_diff_off);
    check(n_diff_elastic == 0, "elastic updates of DP/MC equal linear elasticity bit for bit", n_diff_elastic);
    check(n_plastic_on > 100 && n_elastic > 100, "switch test exercises both elastic and plastic updates");
  }
} // namespace

int main()
{
  test_eigen();
  test_switch_and_elastic_path();

  std::mt19937 rng(2024);
  const int    n = 5000;
  int          dp_modes[4] = {0, 0, 0, 0};
  const double apex = 1e30; // cut-off at the apex (ep2-3De)
  const DPCase dp_cases[] = {
    {30 * deg, 30 * deg, 2e4, apex, 0.3},  {30 * deg, 30 * deg, 2e4, 5e3, 0.3}, {30 * deg, 0, 2e4, 5e3, 0.3},
    {30 * deg, 10 * deg, 2e4, 0, 0.3},     {19.8 * deg, 0, 0, apex, 0.3},       {40 * deg, 40 * deg, 1e4, 2e3, 0.45},
    {40 * deg, 20 * deg, 1e4, 2e3, 0.49},  {20 * deg, 20 * deg, 0, apex, 0.2},  {0, 0, 3e4, 1e4, 0.3},
  };
  for (const DPCase &c : dp_cases)
    test_drucker_prager(c, rng, n, dp_modes);
  std::printf("DP modes: elastic %d shear %d tension %d corner %d\n", dp_modes[0], dp_modes[1], dp_modes[2],
              dp_modes[3]);
  for (int i = 0; i < 4; ++i)
    check(dp_modes[i] > 200, "DP: every return mode exercised", dp_modes[i]);

  int          mc_modes[7] = {0, 0, 0, 0, 0, 0, 0};
  const MCCase mc_cases[] = {
    {30 * deg, 30 * deg, 2e4, 0.3}, {30 * deg, 10 * deg, 2e4, 0.3}, {19.8 * deg, 5 * deg, 0, 0.3},
    {40 * deg, 40 * deg, 1e4, 0.45}, {40 * deg, 20 * deg, 1e4, 0.49}, {20 * deg, 20 * deg, 0, 0.2},
    {0, 0, 3e4, 0.3},
  };
  for (const MCCase &c : mc_cases)
    test_mohr_coulomb(c, rng, n, mc_modes);
  std::printf("MC modes: elastic %d plane %d edge-extension %d edge-compression %d apex %d\n", mc_modes[0],
              mc_modes[1], mc_modes[4], mc_modes[5], mc_modes[6]);
  for (const int i : {0, 1, 4, 5, 6})
    check(mc_modes[i] > 200, "MC: every return mode exercised", mc_modes[i]);
  return mpm_test::finish("test_return_mapping");
}
