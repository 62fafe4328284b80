// The Jaumann (Hughes-Winget) update is objective: under a pure rigid rotation
// (zero strain increment) the stress invariants stay constant to round-off, and the
// stress turns with the body by the Hughes-Winget angle 2 atan(w dt / 2) per step;
// a strain increment alone follows Hooke's law.
#include <mpm/core/material/material.h>

#include "check.h"

#include <random>

using namespace mpm;

int main()
{
  std::mt19937                           rng(3);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  MaterialParameters<double>             m;
  m.model                  = MaterialModel::linear_elastic;
  m.elastic.youngs_modulus = 1e7;
  m.elastic.poissons_ratio = 0.3;

  double worst_invariants = 0, worst_angle = 0;
  for (int trial = 0; trial < 200; ++trial)
    {
      MaterialPointState<double> state;
      for (int c = 0; c < n_voigt; ++c)
        state.stress[c] = 1e5 * u(rng);
      state.plastic_strain = 0;
      const SymTensor<double> initial = state.stress;

      // random axis and rate
      double w[3] = {u(rng), u(rng), u(rng)};
      if (trial % 4 == 0) // spin about z only: rotate_jaumann's closed form for the plane case
        w[0] = w[1] = 0;
      const double norm = std::sqrt(w[0] * w[0] + w[1] * w[1] + w[2] * w[2]);
      for (double &c : w)
        c /= norm;
      const double omega = 3 * u(rng), dt = 1e-2;
      Mat3<double> dW = Mat3<double>::zero();
      dW.a[0][1] = -w[2] * omega * dt, dW.a[1][0] = w[2] * omega * dt;
      dW.a[0][2] = w[1] * omega * dt, dW.a[2][0] = -w[1] * omega * dt;
      dW.a[1][2] = -w[0] * omega * dt, dW.a[2][1] = w[0] * omega * dt;
      const SymTensor<double> zero = SymTensor<double>::zero();
      const int n_steps = 1000;
      for (int s = 0; s < n_steps; ++s)
        update_stress(m, zero, dW, state);

      const double scale = 1e5;
      worst_invariants   = std::max(worst_invariants, std::abs(mean_stress(state.stress) - mean_stress(initial)) / scale);
      worst_invariants   = std::max(worst_invariants, std::abs(std::sqrt(second_deviatoric_invariant(state.stress)) -
                                                          std::sqrt(second_deviatoric_invariant(initial))) / scale);
      worst_invariants   = std::max(worst_invariants, std::abs(std::cbrt(third_invariant(state.stress)) -
                                                          std::cbrt(third_invariant(initial))) / scale);

      // Expected: R sigma R^T with R the rotation about w by n_steps * 2 atan(omega dt / 2).
      const double theta = n_steps * 2 * std::atan(omega * dt / 2);
      const double c = std::cos(theta), s = std::sin(theta), t = 1 - c;
      Mat3<double> R;
      R.a[0][0] = c + w[0] * w[0] * t, R.a[0][1] = w[0] * w[1] * t - w[2] * s, R.a[0][2] = w[0] * w[2] * t + w[1] * s;
      R.a[1][0] = w[1] * w[0] * t + w[2] * s, R.a[1][1] = c + w[1] * w[1] * t, R.a[1][2] = w[1] * w[2] * t - w[0] * s;
      R.a[2][0] = w[2] * w[0] * t - w[1] * s, R.a[2][1] = w[2] * w[1] * t + w[0] * s, R.a[2][2] = c + w[2] * w[2] * t;
      const SymTensor<double> expected =
        symmetric_part(multiply(multiply(R, to_matrix(initial)), transpose(R)));
      for (int k = 0; k < n_voigt; ++k)
        worst_angle = std::max(worst_angle, std::abs(expected[k] - state.stress[k]) / scale);
    }
  std::printf("rigid rotation, 1000 increments: invariants drift %.2e, stress vs exact rotation %.2e (of |sigma|)\n",
              worst_invariants, worst_angle);
  mpm_test::check_below(worst_invariants, 1e-12, "invariants under rigid rotation");
  mpm_test::check_below(worst_angle, 1e-11, "stress rotates with the body");

  // A strain increment alone follows Hooke's law: uniaxial strain gives lambda+2G and lambda.
  MaterialPointState<double> state;
  state.stress = SymTensor<double>::zero();
  SymTensor<double> d_eps = SymTensor<double>::zero();
  d_eps[0]               = 1e-4;
  update_stress(m, d_eps, Mat3<double>::zero(), state);
  const double G = m.elastic.shear_modulus(), lambda = m.elastic.bulk_modulus() - 2 * G / 3;
  mpm_test::check_below(std::abs(state.stress[0] - (lambda + 2 * G) * 1e-4) / (G * 1e-4), 1e-13, "Hooke xx");
  mpm_test::check_below(std::abs(state.stress[1] - lambda * 1e-4) / (G * 1e-4), 1e-13, "Hooke yy");
  return mpm_test::finish("test_jaumann_rotation");
}
