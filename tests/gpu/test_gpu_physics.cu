// The point-wise physics on the device: tests/core/test_shape_functions.cc and
// tests/core/test_jaumann_rotation.cc evaluated in kernels (CudaBackend::gather_points)
// and checked against the same properties and against the host evaluation of the same
// functions. The device may contract a*b+c into an FMA, so device and host agree to a
// few units of round-off, not bitwise.
#include "../core/check.h"
#include "gpu_targets.h"

#include <mpm/core/interpolation.h>
#include <mpm/core/material/material.h>
#include <mpm/core/shape_functions.h>

#include <random>
#include <vector>

using namespace mpm;
using namespace mpm_test;

// Host-side visitor comparing the host's stencil with the device's records (a functor with
// an MPM_HOST_DEVICE call operator, as for_each_stencil_node is MPM_HOST_DEVICE).
template <int dim>
struct HostStencilCheck
{
  const int    *node;
  const double *N, *grad;
  double        h;
  int           k = 0, mismatches = 0;
  double        worst = 0;
  MPM_HOST_DEVICE void operator()(const int n, const double Nh, const double *gh)
  {
    if (node[k] != n)
      ++mismatches;
    const double e = std::fabs(Nh - N[k]);
    worst          = e > worst ? e : worst;
    for (int d = 0; d < dim; ++d)
      {
        const double eg = std::fabs(gh[d] - grad[k * dim + d]) * h;
        worst           = eg > worst ? eg : worst;
      }
    ++k;
  }
};

template <int dim, typename Shape>
void shape_functions(const char *name, std::mt19937 &rng)
{
  constexpr int n_stencil = dim == 2 ? Shape::n_per_direction * Shape::n_per_direction :
                                       Shape::n_per_direction * Shape::n_per_direction * Shape::n_per_direction;
  HostGrid<dim, double> grid;
  const double          lower[3] = {-1.0, 0.5, 2.0};
  const int             cells[3] = {7, 5, 6};
  grid.make_dense(lower, 0.37, cells);
  HostPoints<dim, double> no_points;
  CudaTarget<dim, double> target(grid, no_points, {});
  const GridView<dim, double> g_host = grid.view();
  const GridView<dim, double> g_dev  = target.grid();

  const int                              n_trials = 4000;
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::vector<double>                    x(n_trials * dim), lp(n_trials * dim);
  for (int t = 0; t < n_trials; ++t)
    for (int d = 0; d < dim; ++d)
      {
        lp[t * dim + d] = (0.01 + 0.49 * u(rng)) * grid.h;
        x[t * dim + d]  = grid.origin[d] + lp[t * dim + d] + u(rng) * (grid.n_cells[d] * grid.h - 2 * lp[t * dim + d]);
      }
  DeviceArray<double> x_dev, lp_dev, N_dev(n_trials * n_stencil), grad_dev(n_trials * n_stencil * dim);
  DeviceArray<int>    node_dev(n_trials * n_stencil);
  x_dev.upload(x);
  lp_dev.upload(lp);
  N_dev.fill_bytes(0xff); // NaN poison: every slot must be written
  grad_dev.fill_bytes(0xff);
  node_dev.fill_bytes(0xff);
  const double *xs = x_dev.data(), *lps = lp_dev.data();
  double       *Ns = N_dev.data(), *grads = grad_dev.data();
  int          *nodes = node_dev.data();
  target.backend.gather_points(n_trials, [=] MPM_HOST_DEVICE(const int t) {
    for (int k = 0; k < n_stencil; ++k)
      {
        Ns[t * n_stencil + k]    = 0;
        nodes[t * n_stencil + k] = -1;
        for (int d = 0; d < dim; ++d)
          grads[(t * n_stencil + k) * dim + d] = 0;
      }
    int k = 0;
    for_each_stencil_node<dim, Shape>(g_dev, xs + t * dim, lps + t * dim, [&](int n, double N, const double *grad) {
      Ns[t * n_stencil + k]    = N;
      nodes[t * n_stencil + k] = n;
      for (int d = 0; d < dim; ++d)
        grads[(t * n_stencil + k) * dim + d] = grad[d];
      ++k;
    });
  });
  std::vector<double> N, grad;
  std::vector<int>    node;
  N_dev.download(N);
  grad_dev.download(grad);
  node_dev.download(node);

  double worst_sum = 0, worst_grad = 0, worst_host = 0;
  int    node_mismatch = 0;
  for (int t = 0; t < n_trials; ++t)
    {
      double sum = 0, grad_sum[dim] = {};
      for (int k = 0; k < n_stencil; ++k)
        {
          sum += N[t * n_stencil + k];
          for (int d = 0; d < dim; ++d)
            grad_sum[d] += grad[(t * n_stencil + k) * dim + d];
        }
      worst_sum = std::max(worst_sum, std::abs(sum - 1.0));
      for (int d = 0; d < dim; ++d)
        worst_grad = std::max(worst_grad, std::abs(grad_sum[d]) * grid.h);
      HostStencilCheck<dim> visit{&node[t * n_stencil], &N[t * n_stencil], &grad[t * n_stencil * dim], grid.h};
      for_each_stencil_node<dim, Shape>(g_host, &x[t * dim], &lp[t * dim], visit);
      node_mismatch += visit.mismatches;
      worst_host = std::max(worst_host, visit.worst);
    }
  std::printf("GPU %s %dD: max |sum N - 1| = %.2e, max |sum grad N| h = %.2e, device vs host %.2e, node mismatches %d\n",
              name, dim, worst_sum, worst_grad, worst_host, node_mismatch);
  check_below(worst_sum, 1e-14, "device: partition of unity");
  check_below(worst_grad, 1e-13, "device: gradients sum to zero");
  check_below(worst_host, 1e-14, "device weights and gradients equal the host's to round-off");
  check(node_mismatch == 0, "device and host visit the same nodes");
}

void jaumann_rotation()
{
  std::mt19937                           rng(3);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  MaterialParameters<double>             m;
  m.model                  = MaterialModel::linear_elastic;
  m.elastic.youngs_modulus = 1e7;
  m.elastic.poissons_ratio = 0.3;

  const int           n_trials = 512, n_steps = 1000;
  std::vector<double> sigma(n_trials * n_voigt), spin(n_trials * 9, 0.0);
  for (int t = 0; t < n_trials; ++t)
    {
      for (int c = 0; c < n_voigt; ++c)
        sigma[t * n_voigt + c] = 1e5 * u(rng);
      double       w[3] = {u(rng), u(rng), u(rng)};
      const double norm = std::sqrt(w[0] * w[0] + w[1] * w[1] + w[2] * w[2]);
      const double wdt  = 3 * u(rng) * 1e-2;
      for (double &c : w)
        c *= wdt / norm;
      double *W = &spin[t * 9];
      W[1] = -w[2], W[3] = w[2], W[2] = w[1], W[6] = -w[1], W[5] = -w[0], W[7] = w[0];
    }
  HostGrid<3, double>   grid;
  const double          lower[3] = {0, 0, 0};
  const int             cells[3] = {1, 1, 1};
  grid.make_dense(lower, 1.0, cells);
  HostPoints<3, double> none;
  CudaTarget<3, double> target(grid, none, {m});
  DeviceArray<double>   sigma_dev, spin_dev;
  sigma_dev.upload(sigma);
  spin_dev.upload(spin);
  double                           *S     = sigma_dev.data();
  const double                     *Wd    = spin_dev.data();
  const MaterialParameters<double> *table = target.material_table();
  target.backend.gather_points(n_trials, [=] MPM_HOST_DEVICE(const int t) {
    MaterialPointState<double> state;
    for (int c = 0; c < n_voigt; ++c)
      state.stress[c] = S[t * n_voigt + c];
    state.plastic_strain = 0;
    Mat3<double> dW;
    for (int a = 0; a < 3; ++a)
      for (int b = 0; b < 3; ++b)
        dW.a[a][b] = Wd[t * 9 + a * 3 + b];
    const SymTensor<double> zero = SymTensor<double>::zero();
    for (int s = 0; s < n_steps; ++s)
      update_stress(table[0], zero, dW, state);
    for (int c = 0; c < n_voigt; ++c)
      S[t * n_voigt + c] = state.stress[c];
  });
  std::vector<double> result;
  sigma_dev.download(result);

  double worst_invariants = 0, worst_host = 0;
  for (int t = 0; t < n_trials; ++t)
    {
      MaterialPointState<double> host, initial, device;
      for (int c = 0; c < n_voigt; ++c)
        {
          host.stress[c]   = initial.stress[c] = sigma[t * n_voigt + c];
          device.stress[c] = result[t * n_voigt + c];
        }
      host.plastic_strain = 0;
      Mat3<double> dW;
      for (int a = 0; a < 3; ++a)
        for (int b = 0; b < 3; ++b)
          dW.a[a][b] = spin[t * 9 + a * 3 + b];
      for (int s = 0; s < n_steps; ++s)
        update_stress(m, SymTensor<double>::zero(), dW, host);
      const double scale = 1e5;
      worst_invariants   = std::max(worst_invariants, std::abs(mean_stress(device.stress) - mean_stress(initial.stress)) / scale);
      worst_invariants   = std::max(worst_invariants, std::abs(std::sqrt(second_deviatoric_invariant(device.stress)) -
                                                          std::sqrt(second_deviatoric_invariant(initial.stress))) / scale);
      for (int c = 0; c < n_voigt; ++c)
        worst_host = std::max(worst_host, std::abs(device.stress[c] - host.stress[c]) / scale);
    }
  std::printf("GPU rigid rotation, 1000 increments: invariants drift %.2e, device vs host %.2e (of |sigma|)\n",
              worst_invariants, worst_host);
  check_below(worst_invariants, 1e-12, "device: invariants under rigid rotation");
  check_below(worst_host, 1e-12, "device stress update equals the host's to round-off");
}

int main()
{
  if (!cuda_device_present("test_gpu_physics"))
    return skip_code;
  try
    {
      std::mt19937 rng(42);
      shape_functions<2, LinearShape>("linear", rng);
      shape_functions<3, LinearShape>("linear", rng);
      shape_functions<2, GimpShape>("GIMP", rng);
      shape_functions<3, GimpShape>("GIMP", rng);
      shape_functions<2, QuadraticBSplineShape>("quadratic B-spline", rng);
      shape_functions<3, QuadraticBSplineShape>("quadratic B-spline", rng);
      jaumann_rotation();
    }
  catch (const std::exception &e)
    {
      std::printf("exception: %s\n", e.what());
      return 1;
    }
  return finish("test_gpu_physics");
}
