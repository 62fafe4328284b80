#include <mpm/fields/gaussian_random_field.h>

#include <fftw3.h>

#include <algorithm>
#include <cmath>
#include <complex>
#include <random>
#include <stdexcept>

namespace mpm
{
  namespace
  {
    // RAII for FFTW's aligned buffers.
    template <typename T>
    struct FftwBuffer
    {
      T *data;
      explicit FftwBuffer(const size_t n)
        : data(static_cast<T *>(fftw_malloc(sizeof(T) * n)))
      {
        if (data == nullptr)
          throw std::runtime_error("random field: out of memory for the FFT buffers");
      }
      ~FftwBuffer() { fftw_free(data); }
    };
  } // namespace

  template <int dim>
  GaussianRandomField<dim>::GaussianRandomField(const RandomFieldParameters &p, const std::array<double, dim> &lower,
                                                const std::array<double, dim> &upper, const double h)
    : origin(lower)
    , spacing(h)
  {
    if (p.correlation_length.size() != dim)
      throw std::invalid_argument("random field: one correlation length per dimension is needed");
    for (const double L : p.correlation_length)
      if (!(L > 0))
        throw std::invalid_argument("random field: correlation lengths must be > 0");

    // Embedding: the lattice plus a margin of 6 correlation lengths, so that the
    // periodic covariance has decayed (exp(-6) or exp(-36)) before it wraps around.
    int    m[dim];
    size_t n_total = 1, n_complex = 1;
    for (int d = 0; d < dim; ++d)
      {
        n[d] = static_cast<int>(std::ceil((upper[d] - lower[d]) / h)) + 1;
        m[d] = n[d] + static_cast<int>(std::ceil(6 * p.correlation_length[d] / h));
        m[d] += m[d] % 2;
        n_total *= m[d];
        n_complex *= d + 1 < dim ? m[d] : m[d] / 2 + 1;
      }

    // First row of the block-circulant covariance (periodic distances).
    FftwBuffer<double>       real(n_total);
    FftwBuffer<fftw_complex> spectrum(n_complex), noise(n_complex);
    for (size_t j = 0; j < n_total; ++j)
      {
        size_t rest = j;
        double r2   = 0;
        for (int d = dim - 1; d >= 0; --d) // row-major: last index fastest
          {
            const int k  = static_cast<int>(rest % m[d]);
            rest /= m[d];
            const double r = std::min(k, m[d] - k) * h / p.correlation_length[d];
            r2 += r * r;
          }
        real.data[j] = p.covariance == Covariance::gaussian ? std::exp(-r2) : std::exp(-std::sqrt(r2));
      }
    fftw_plan to_spectrum = fftw_plan_dft_r2c(dim, m, real.data, spectrum.data, FFTW_ESTIMATE);
    fftw_execute(to_spectrum);
    fftw_destroy_plan(to_spectrum);

    // White noise, to the spectrum, scaled by sqrt(lambda), back: covariance = the row above.
    std::mt19937_64                  rng(p.seed);
    std::normal_distribution<double> normal(0.0, 1.0);
    for (size_t j = 0; j < n_total; ++j)
      real.data[j] = normal(rng);
    fftw_plan noise_forward = fftw_plan_dft_r2c(dim, m, real.data, noise.data, FFTW_ESTIMATE);
    fftw_execute(noise_forward);
    fftw_destroy_plan(noise_forward);

    double total = 0, negative = 0;
    for (size_t k = 0; k < n_complex; ++k)
      {
        const double lambda = spectrum.data[k][0];
        total += std::abs(lambda);
        if (lambda < 0)
          negative -= lambda;
        const double scale = std::sqrt(std::max(lambda, 0.0)) / n_total;
        noise.data[k][0] *= scale;
        noise.data[k][1] *= scale;
      }
    clipped = total > 0 ? negative / total : 0;
    fftw_plan back = fftw_plan_dft_c2r(dim, m, noise.data, real.data, FFTW_ESTIMATE);
    fftw_execute(back);
    fftw_destroy_plan(back);

    // Keep the lattice part, scaled to the requested mean and standard deviation.
    size_t n_lattice = 1;
    for (int d = 0; d < dim; ++d)
      n_lattice *= n[d];
    values.resize(n_lattice);
    for (size_t i = 0; i < n_lattice; ++i)
      {
        size_t rest = i, j = 0;
        int    idx[dim];
        for (int d = 0; d < dim; ++d) // values: first index fastest
          {
            idx[d] = static_cast<int>(rest % n[d]);
            rest /= n[d];
          }
        for (int d = 0; d < dim; ++d)
          j = j * m[d] + idx[d];
        values[i] = p.mean + p.standard_deviation * real.data[j];
      }
  }

  template <int dim>
  double GaussianRandomField<dim>::value(const std::array<double, dim> &x) const
  {
    int    base[dim];
    double t[dim];
    for (int d = 0; d < dim; ++d)
      {
        const double s = std::clamp((x[d] - origin[d]) / spacing, 0.0, double(n[d] - 1));
        base[d]        = std::min(static_cast<int>(s), n[d] - 2 < 0 ? 0 : n[d] - 2);
        t[d]           = s - base[d];
      }
    double result = 0;
    for (int corner = 0; corner < (1 << dim); ++corner)
      {
        double w     = 1;
        size_t index = 0, stride = 1;
        for (int d = 0; d < dim; ++d)
          {
            const int bit = (corner >> d) & 1;
            w *= bit ? t[d] : 1 - t[d];
            index += size_t(std::min(base[d] + bit, n[d] - 1)) * stride;
            stride *= n[d];
          }
        result += w * values[index];
      }
    return result;
  }

  template class GaussianRandomField<2>;
  template class GaussianRandomField<3>;
} // namespace mpm
