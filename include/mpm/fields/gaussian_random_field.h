// Stationary Gaussian random fields for heterogeneous material parameters, generated on a
// regular lattice by circulant embedding (FFTW does the transforms) and sampled at the
// material points by multilinear interpolation. The same seed gives the same field on
// every rank, so runs stay independent of the number of MPI ranks.
#pragma once

#include <array>
#include <vector>

namespace mpm
{
  enum class Covariance
  {
    gaussian,   // C(r) = sigma^2 exp(-sum_d (r_d / L_d)^2)
    exponential // C(r) = sigma^2 exp(-sqrt(sum_d (r_d / L_d)^2))
  };

  struct RandomFieldParameters
  {
    Covariance          covariance = Covariance::gaussian;
    std::vector<double> correlation_length; // L_d, one per dimension (m)
    double              mean               = 0;
    double              standard_deviation = 0;
    unsigned int        seed               = 1;
  };

  template <int dim>
  class GaussianRandomField
  {
  public:
    // The field covers [lower, upper] with lattice spacing `spacing` (use <= L/4 for a
    // faithful Gaussian covariance).
    GaussianRandomField(const RandomFieldParameters &parameters, const std::array<double, dim> &lower,
                        const std::array<double, dim> &upper, double spacing);

    double value(const std::array<double, dim> &x) const;

    // Fraction of the embedding's spectral mass that was negative and clipped to zero
    // (0 for the exponential covariance; tiny for the Gaussian one with enough padding).
    double clipped_fraction() const { return clipped; }

  private:
    std::array<double, dim> origin;
    double                  spacing;
    std::array<int, dim>    n; // lattice points per direction
    std::vector<double>     values;
    double                  clipped = 0;
  };
} // namespace mpm
