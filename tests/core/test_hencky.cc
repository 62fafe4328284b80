// Hencky's finite-strain elasticity and multiplicative plasticity (hencky.h), driven through
// update_stress by homogeneous deformation paths F(t) in many increments, as the MPM step
// drives it (f = F_{k+1} F_k^-1, L dt = f - I):
// - uniaxial strain: sigma_xx = (lambda + 2G) ln(s) / s, sigma_yy = sigma_zz = lambda ln(s) / s,
//   in compression to s = 0.3 and in stretch to s = 2.5, to round-off;
// - simple shear to gamma = 3 against the closed form tau = C : ln V (V from F F^T, 2 x 2
//   eigenvalues in closed form here); the Jaumann rate gives its own known answer
//   (sigma_xy = G sin gamma, Hughes-Winget step) and turns back after gamma = pi / 2;
// - a closed elastic cycle (shear, 50% compression, unshear, release: F ends at I): Hencky
//   returns to zero stress, the Jaumann rate does not (the failure of hypoelasticity at large
//   elastic strain: doc/methods.md, stability matrix);
// - Drucker-Prager and Mohr-Coulomb through Hencky: the stress stays on the yield surface,
//   and at small strain the result is the Jaumann update's.
#include <mpm/core/material/material.h>

#include "check.h"

#include <cmath>
#include <cstdio>

using namespace mpm;

namespace
{
  Mat3<double> inverse(const Mat3<double> &m)
  {
    const double d = determinant(m);
    Mat3<double> r;
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j)
        {
          const int i1 = (j + 1) % 3, i2 = (j + 2) % 3, j1 = (i + 1) % 3, j2 = (i + 2) % 3;
          r.a[i][j] = (m.a[i1][j1] * m.a[i2][j2] - m.a[i1][j2] * m.a[i2][j1]) / d;
        }
    return r;
  }

  // Drives the material from F_from to F_to in n equal steps of F (linear in the entries).
  void drive(const MaterialParameters<double> &m, const Mat3<double> &F_from, const Mat3<double> &F_to, const int n,
             MaterialPointState<double> &state)
  {
    for (int k = 0; k < n; ++k)
      {
        Mat3<double> F0, F1;
        for (int i = 0; i < 3; ++i)
          for (int j = 0; j < 3; ++j)
            {
              F0.a[i][j] = F_from.a[i][j] + (F_to.a[i][j] - F_from.a[i][j]) * k / n;
              F1.a[i][j] = F_from.a[i][j] + (F_to.a[i][j] - F_from.a[i][j]) * (k + 1) / n;
            }
        StepKinematics<double> kin;
        kin.f = multiply(F1, inverse(F0));
        Mat3<double> Ldt;
        for (int i = 0; i < 3; ++i)
          for (int j = 0; j < 3; ++j)
            {
              Ldt.a[i][j]        = kin.f.a[i][j] - (i == j ? 1.0 : 0.0);
              kin.d_spin.a[i][j] = 0;
            }
        for (int i = 0; i < 3; ++i)
          for (int j = 0; j < 3; ++j)
            kin.d_spin.a[i][j] = 0.5 * (Ldt.a[i][j] - Ldt.a[j][i]);
        kin.d_eps = symmetric_part(Ldt);
        kin.J     = determinant(F0);
        kin.J_new = determinant(F1);
        update_stress(m, kin, state);
      }
  }

  Mat3<double> deformation(const double sxx, const double gxy)
  {
    Mat3<double> F = Mat3<double>::identity();
    F.a[0][0]      = sxx;
    F.a[0][1]      = gxy;
    return F;
  }

  // Hencky's Cauchy stress of F = [[a, b], [0, 1]] (plane), from the 2 x 2 eigen decomposition
  // of b = F F^T in closed form.
  SymTensor<double> hencky_exact(const LinearElasticParameters<double> &p, const double a, const double g)
  {
    const double bxx = a * a + g * g, bxy = g, byy = 1;
    const double mean = (bxx + byy) / 2, radius = std::sqrt((bxx - byy) * (bxx - byy) / 4 + bxy * bxy);
    const double l1 = mean + radius, l2 = mean - radius;
    const double e1 = 0.5 * std::log(l1), e2 = 0.5 * std::log(l2);
    // eigenvector of l1: (bxy, l1 - bxx) or (l1 - byy, bxy)
    double vx = l1 - byy, vy = bxy;
    if (std::abs(vx) + std::abs(vy) < 1e-300)
      vx = 1, vy = 0;
    const double n = std::hypot(vx, vy);
    vx /= n, vy /= n;
    // ln V = e1 v v^T + e2 (I - v v^T) in the plane, 0 out of it
    const double exx = e2 + (e1 - e2) * vx * vx, eyy = e2 + (e1 - e2) * vy * vy, exy = (e1 - e2) * vx * vy;
    const double G = p.shear_modulus(), lambda = p.bulk_modulus() - 2 * G / 3, J = a;
    SymTensor<double> s = SymTensor<double>::zero();
    s[0]                = (lambda * (exx + eyy) + 2 * G * exx) / J;
    s[1]                = (lambda * (exx + eyy) + 2 * G * eyy) / J;
    s[2]                = lambda * (exx + eyy) / J;
    s[3]                = 2 * G * exy / J;
    return s;
  }

  double largest_difference(const SymTensor<double> &a, const SymTensor<double> &b)
  {
    double d = 0;
    for (int c = 0; c < n_voigt; ++c)
      d = std::max(d, std::abs(a[c] - b[c]));
    return d;
  }
} // namespace

int main()
{
  MaterialParameters<double> hencky;
  hencky.model                  = MaterialModel::linear_elastic;
  hencky.elastic.youngs_modulus = 1e7;
  hencky.elastic.poissons_ratio = 0.3;
  hencky.elastic_law            = ElasticLaw::hencky;
  MaterialParameters<double> jaumann = hencky;
  jaumann.elastic_law                = ElasticLaw::jaumann_rate;
  const double G = hencky.elastic.shear_modulus(), lambda = hencky.elastic.bulk_modulus() - 2 * G / 3;
  const Mat3<double> I = Mat3<double>::identity();

  // Uniaxial strain, in compression and in stretch.
  for (const double s : {0.3, 2.5})
    {
      MaterialPointState<double> state;
      state.stress         = SymTensor<double>::zero();
      state.plastic_strain = 0;
      drive(hencky, I, deformation(s, 0), 500, state);
      SymTensor<double> exact = SymTensor<double>::zero();
      exact[0]                = (lambda + 2 * G) * std::log(s) / s;
      exact[1] = exact[2] = lambda * std::log(s) / s;
      const double error  = largest_difference(state.stress, exact) / G;
      std::printf("uniaxial strain to s = %.1f: sigma_xx %.6e (exact %.6e), error %.1e G\n", s, state.stress[0],
                  exact[0], error);
      mpm_test::check_below(error, 1e-12, "Hencky uniaxial strain, exact in any number of increments");
    }

  // Simple shear to gamma = 3.
  {
    MaterialPointState<double> h, j;
    h.stress = j.stress = SymTensor<double>::zero();
    h.plastic_strain = j.plastic_strain = 0;
    const int    n      = 9000;
    double       worst  = 0, jaumann_peak = 0;
    for (int k = 0; k < 30; ++k)
      {
        const double g0 = 0.1 * k, g1 = 0.1 * (k + 1);
        drive(hencky, deformation(1, g0), deformation(1, g1), n / 30, h);
        drive(jaumann, deformation(1, g0), deformation(1, g1), n / 30, j);
        worst        = std::max(worst, largest_difference(h.stress, hencky_exact(hencky.elastic, 1, g1)) / G);
        jaumann_peak = std::max(jaumann_peak, j.stress[3]);
      }
    const double jaumann_error = std::abs(j.stress[3] - G * std::sin(3.0)) / G;
    std::printf("simple shear to 3: Hencky sigma_xy %.4f G, worst error %.1e G; Jaumann sigma_xy %.4f G "
                "(G sin 3 = %.4f G, error %.1e), its peak %.4f G\n",
                h.stress[3] / G, worst, j.stress[3] / G, std::sin(3.0), jaumann_error, jaumann_peak / G);
    mpm_test::check_below(worst, 1e-11, "Hencky simple shear against the closed form");
    mpm_test::check_below(jaumann_error, 1e-3, "Jaumann simple shear: G sin(gamma) (first order in the step)");
    mpm_test::check(j.stress[3] < 0.2 * jaumann_peak, "Jaumann's shear stress turns back (hypoelastic failure)",
                    j.stress[3], 0.2 * jaumann_peak);
    mpm_test::check(h.stress[3] > 0.5 * G, "Hencky's shear stress keeps its sign and size", h.stress[3] / G, 0.5);
  }

  // A closed elastic cycle with 50% compression.
  {
    MaterialPointState<double> h, j;
    h.stress = j.stress = SymTensor<double>::zero();
    h.plastic_strain = j.plastic_strain = 0;
    const Mat3<double> corners[5] = {I, deformation(1, 1), deformation(0.5, 1), deformation(0.5, 0), I};
    for (int leg = 0; leg < 4; ++leg)
      {
        drive(hencky, corners[leg], corners[leg + 1], 2000, h);
        drive(jaumann, corners[leg], corners[leg + 1], 2000, j);
      }
    const double residual_h = largest_difference(h.stress, SymTensor<double>::zero()) / G;
    const double residual_j = largest_difference(j.stress, SymTensor<double>::zero()) / G;
    std::printf("closed cycle (shear 1, compress to 0.5, unshear, release): residual stress Hencky %.1e G, "
                "Jaumann %.3e G\n",
                residual_h, residual_j);
    mpm_test::check_below(residual_h, 1e-11, "Hencky: no stress after a closed elastic cycle");
    mpm_test::check(residual_j > 1e-2, "Jaumann: stress left after a closed elastic cycle", residual_j, 1e-2);
  }

  // Plasticity through Hencky: on the yield surface after the return, and the Jaumann result at small strain.
  for (const MaterialModel model : {MaterialModel::drucker_prager, MaterialModel::mohr_coulomb})
    {
      MaterialParameters<double> p = hencky;
      p.model                      = model;
      SofteningStrength<double> strength{};
      strength.cohesion = strength.residual_cohesion = 1e4;
      strength.friction_angle = strength.residual_friction_angle = 30 * M_PI / 180;
      strength.dilatancy_angle                                   = 0;
      p.drucker_prager.strength                                  = strength;
      p.mohr_coulomb.strength                                    = strength;
      MaterialParameters<double> q                               = p;
      q.elastic_law                                              = ElasticLaw::jaumann_rate;
      const char *name = model == MaterialModel::drucker_prager ? "Drucker-Prager" : "Mohr-Coulomb";

      // Small strain (shear 1e-3 and a 1e-4 compression): Hencky = Jaumann to O(strain).
      // A cohesion of 1 kPa, so that it yields (G gamma = 3.8 kPa).
      MaterialParameters<double> p_weak = p, q_weak = q;
      for (MaterialParameters<double> *w : {&p_weak, &q_weak})
        w->drucker_prager.strength.cohesion = w->drucker_prager.strength.residual_cohesion =
          w->mohr_coulomb.strength.cohesion = w->mohr_coulomb.strength.residual_cohesion = 1e3;
      MaterialPointState<double> a, b;
      a.stress = b.stress = SymTensor<double>::zero();
      a.plastic_strain = b.plastic_strain = 0;
      const Mat3<double> small = deformation(1 - 1e-4, 1e-3);
      drive(p_weak, I, small, 200, a);
      drive(q_weak, I, small, 200, b);
      const double scale = std::sqrt(second_deviatoric_invariant(b.stress));
      const double small_difference = largest_difference(a.stress, b.stress) / scale;
      std::printf("%s, small strain: Hencky vs Jaumann %.1e of the shear stress; eps_p %.3e vs %.3e\n", name,
                  small_difference, a.plastic_strain, b.plastic_strain);
      mpm_test::check(b.plastic_strain > 0, "the small-strain path yields", b.plastic_strain, 0);
      mpm_test::check_below(small_difference, 5e-3, "Hencky plasticity = Jaumann's at small strain");
      mpm_test::check_below(std::abs(a.plastic_strain - b.plastic_strain) / b.plastic_strain, 5e-3,
                            "plastic strain at small strain");

      // Large shear: the Kirchhoff stress stays on the surface (a Cauchy stress tau / J, J = 1 here).
      MaterialPointState<double> c;
      c.stress         = SymTensor<double>::zero();
      c.stress[0] = c.stress[1] = c.stress[2] = -5e4;
      c.plastic_strain                        = 0;
      drive(p, I, deformation(1, 2), 4000, c);
      SymTensor<double> once_more = c.stress;
      if (model == MaterialModel::drucker_prager)
        drucker_prager_return(p.elastic, drucker_prager_coefficients_at(p.drucker_prager, c.plastic_strain),
                              once_more);
      else
        mohr_coulomb_return(p.elastic, current_strength(p.mohr_coulomb.strength, c.plastic_strain), once_more);
      const double off_surface = largest_difference(once_more, c.stress) / 5e4;
      std::printf("%s, shear to 2 under 50 kPa: eps_p %.3f, a second return moves the stress by %.1e\n", name,
                  c.plastic_strain, off_surface);
      mpm_test::check(c.plastic_strain > 1, "large shear flows plastically", c.plastic_strain, 1);
      mpm_test::check_below(off_surface, 1e-9, "admissible after the return");
    }
  return mpm_test::finish("test_hencky");
}
