// Gaussian random fields by circulant embedding: the sample mean, standard deviation and
// correlation at lags 0.5 L, L and 2 L along each axis match the prescribed covariance
// (Gaussian and exponential, anisotropic L), within the sampling error of a domain 100
// correlation lengths wide averaged over 4 seeds; same seed -> same field.
#include <mpm/fields/gaussian_random_field.h>

#include "../core/check.h"

#include <cmath>
#include <cstdio>
#include <vector>

using namespace mpm;

namespace
{
  struct Statistics
  {
    double mean = 0, std = 0, correlation[2][3] = {};
  };

  // Field values on the lattice of spacing h over [0, size]^2.
  Statistics statistics(const Covariance covariance, const double Lx, const double Ly, const unsigned seed)
  {
    const double          h = 0.25, size = 100 * std::max(Lx, Ly);
    RandomFieldParameters p;
    p.covariance         = covariance;
    p.correlation_length = {Lx, Ly};
    p.mean               = 20e3;
    p.standard_deviation = 5e3;
    p.seed               = seed;
    GaussianRandomField<2> field(p, {0.0, 0.0}, {size, size}, h);
    const int              n = static_cast<int>(size / h) + 1;
    std::vector<double>    v(size_t(n) * n);
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i)
        v[size_t(j) * n + i] = field.value({i * h, j * h});

    Statistics s;
    for (const double x : v)
      s.mean += x;
    s.mean /= v.size();
    for (const double x : v)
      s.std += (x - s.mean) * (x - s.mean);
    const double variance = s.std / v.size();
    s.std                 = std::sqrt(variance);
    const double lags[3]  = {0.5, 1.0, 2.0};
    for (int axis = 0; axis < 2; ++axis)
      for (int l = 0; l < 3; ++l)
        {
          const int shift = static_cast<int>(std::lround(lags[l] * (axis == 0 ? Lx : Ly) / h));
          double    sum = 0;
          long      count = 0;
          for (int j = 0; j + (axis == 1 ? shift : 0) < n; ++j)
            for (int i = 0; i + (axis == 0 ? shift : 0) < n; ++i)
              {
                const size_t a = size_t(j) * n + i;
                const size_t b = axis == 0 ? a + shift : a + size_t(shift) * n;
                sum += (v[a] - s.mean) * (v[b] - s.mean);
                ++count;
              }
          s.correlation[axis][l] = sum / count / variance;
        }
    return s;
  }
} // namespace

int main()
{
  const double lags[3] = {0.5, 1.0, 2.0};
  for (const Covariance covariance : {Covariance::gaussian, Covariance::exponential})
    {
      const char *name = covariance == Covariance::gaussian ? "gaussian" : "exponential";
      Statistics  mean_stats;
      const int   n_seeds = 4;
      for (unsigned seed = 1; seed <= n_seeds; ++seed)
        {
          const Statistics s = statistics(covariance, 2.0, 1.0, seed);
          mean_stats.mean += s.mean / n_seeds;
          mean_stats.std += s.std / n_seeds;
          for (int a = 0; a < 2; ++a)
            for (int l = 0; l < 3; ++l)
              mean_stats.correlation[a][l] += s.correlation[a][l] / n_seeds;
        }
      std::printf("%s (Lx = 2, Ly = 1, 4 seeds): mean %.1f (20000), std %.1f (5000)\n", name, mean_stats.mean,
                  mean_stats.std);
      // Sampling error: the domain holds ~(100/1.8)^2 ~ 3000 independent patches per seed;
      // over 4 seeds the mean's error is ~5000/sqrt(12000) = 46 and the std's ~1%.
      mpm_test::check_below(std::abs(mean_stats.mean - 20e3), 300, "sample mean (6 sampling errors)");
      mpm_test::check_below(std::abs(mean_stats.std / 5e3 - 1), 0.05, "sample standard deviation (5%)");
      for (int a = 0; a < 2; ++a)
        for (int l = 0; l < 3; ++l)
          {
            const double r     = lags[l];
            const double exact = covariance == Covariance::gaussian ? std::exp(-r * r) : std::exp(-r);
            std::printf("  axis %c lag %.1f L: correlation %.4f (exact %.4f)\n", "xy"[a], r,
                        mean_stats.correlation[a][l], exact);
            mpm_test::check_below(std::abs(mean_stats.correlation[a][l] - exact), 0.02,
                                  "correlation at a lag (0.02: ~3 sampling errors)");
          }
    }

  // Reproducible from the seed; a different seed gives a different field.
  RandomFieldParameters p;
  p.correlation_length = {1.0, 1.0, 1.0};
  p.mean               = 1;
  p.standard_deviation = 0.2;
  p.seed               = 5;
  GaussianRandomField<3> a(p, {0, 0, 0}, {5, 4, 3}, 0.25), b(p, {0, 0, 0}, {5, 4, 3}, 0.25);
  p.seed = 6;
  GaussianRandomField<3> c(p, {0, 0, 0}, {5, 4, 3}, 0.25);
  mpm_test::check(a.value({1.3, 2.1, 0.7}) == b.value({1.3, 2.1, 0.7}), "same seed, same field");
  mpm_test::check(a.value({1.3, 2.1, 0.7}) != c.value({1.3, 2.1, 0.7}), "other seed, other field");
  std::printf("3D Gaussian embedding: clipped spectral fraction %.2e\n", a.clipped_fraction());
  mpm_test::check_below(a.clipped_fraction(), 1e-6, "Gaussian embedding needs no clipping");
  return mpm_test::finish("test_random_field");
}
