// Partition of unity, linear fields reproduced (weights and gradients), and gradients equal
// to the derivative of the weights (finite differences), for the linear, GIMP, quadratic and
// cubic B-spline stencils and the cubic B-spline GIMP at random points, 2D and 3D. The B-splines are
// checked over the whole grid, their folded boundary cells included (GIMP's domains inside the grid).
#include <mpm/core/cubic_bspline_gimp.h>
#include <mpm/core/host_storage.h>
#include <mpm/core/interpolation.h>
#include <mpm/core/shape/test_wide_linear_shape.h>
#include <mpm/core/shape_functions.h>

#include "check.h"

#include <random>
#include <vector>

using namespace mpm;

template <int dim, typename Shape>
void check_family(const char *name, std::mt19937 &rng, const bool whole_grid = false, const double sum_limit = 1e-14)
{
  HostGrid<dim, double> grid;
  const double          lower[3] = {-1.0, 0.5, 2.0};
  const int             cells[3] = {7, 5, 6};
  grid.make_dense(lower, 0.37, cells);
  const GridView<dim, double> g = grid.view();

  std::uniform_real_distribution<double> u(0.0, 1.0);
  double worst_sum = 0, worst_grad = 0, worst_fd = 0, worst_linear = 0, worst_linear_grad = 0;
  int    near_face = 0;
  for (int trial = 0; trial < 2000; ++trial)
    {
      double x[dim], lp[dim];
      for (int d = 0; d < dim; ++d)
        {
          lp[d] = (0.01 + 0.49 * u(rng)) * g.h;
          // keep the particle domain inside the grid, so no weight falls outside it
          x[d] = whole_grid ? g.origin[d] + u(rng) * g.n_cells[d] * g.h :
                              g.origin[d] + lp[d] + u(rng) * (g.n_cells[d] * g.h - 2 * lp[d]);
          // one in four trials within half a cell of a face, where the B-spline folds
          if (whole_grid && trial % 4 == 0 && d == trial / 4 % dim)
            x[d] = trial % 8 == 0 ? g.origin[d] + 0.5 * u(rng) * g.h : g.origin[d] + (g.n_cells[d] - 0.5 * u(rng)) * g.h;
          const double s = (x[d] - g.origin[d]) / g.h;
          near_face += s < 0.5 || s > g.n_cells[d] - 0.5;
        }
      double sum = 0, grad_sum[dim] = {};
      double moment[dim] = {}, moment_grad[dim][dim] = {}; // sum N x_n, sum x_n grad N
      std::vector<double> weight(g.n_nodes, 0.0), gradient(g.n_nodes * dim, 0.0);
      for_each_stencil_node<dim, Shape>(g, x, lp, [&](int n, double N, const double *grad) {
        sum += N;
        int rest = n;
        for (int d = 0; d < dim; ++d)
          {
            const double x_n = g.origin[d] + (rest % (g.n_cells[d] + 1)) * g.h;
            rest /= g.n_cells[d] + 1;
            moment[d] += N * x_n;
            for (int e = 0; e < dim; ++e)
              moment_grad[d][e] += x_n * grad[e];
          }
        weight[n] = N;
        for (int d = 0; d < dim; ++d)
          {
            grad_sum[d] += grad[d];
            gradient[n * dim + d] = grad[d];
          }
        mpm_test::check(N >= -1e-15, "weights are non-negative", N, 0);
      });
      worst_sum = std::max(worst_sum, std::abs(sum - 1.0));
      for (int d = 0; d < dim; ++d)
        {
          worst_grad   = std::max(worst_grad, std::abs(grad_sum[d]) * g.h);
          worst_linear = std::max(worst_linear, std::abs(moment[d] - x[d]) / g.h);
          for (int e = 0; e < dim; ++e)
            worst_linear_grad = std::max(worst_linear_grad, std::abs(moment_grad[d][e] - (d == e ? 1.0 : 0.0)));
        }

      // central differences of the weights along each direction
      const double eps = 1e-6 * g.h;
      for (int d = 0; d < dim; ++d)
        {
          double xp[dim], xm[dim];
          for (int e = 0; e < dim; ++e)
            xp[e] = xm[e] = x[e];
          xp[d] += eps;
          xm[d] -= eps;
          std::vector<double> wp(g.n_nodes, 0.0), wm(g.n_nodes, 0.0);
          for_each_stencil_node<dim, Shape>(g, xp, lp, [&](int n, double N, const double *) { wp[n] = N; });
          for_each_stencil_node<dim, Shape>(g, xm, lp, [&](int n, double N, const double *) { wm[n] = N; });
          for (int n = 0; n < g.n_nodes; ++n)
            {
              const double fd = (wp[n] - wm[n]) / (2 * eps);
              // linear weights have kinks at nodes: skip points within eps of one
              if (std::abs(fd - gradient[n * dim + d]) * g.h > 1e-4)
                {
                  const double s = (x[d] - g.origin[d]) / g.h;
                  if (std::abs(s - std::round(s)) * g.h < 10 * eps)
                    continue;
                }
              worst_fd = std::max(worst_fd, std::abs(fd - gradient[n * dim + d]) * g.h);
            }
        }
    }
  std::printf("%s %dD: max |sum N - 1| = %.2e, max |sum grad N| h = %.2e, max |sum N x_n - x| / h = %.2e, "
              "max |sum x_n grad N - I| = %.2e, max gradient vs FD = %.2e (%d coordinates within h/2 of a face)\n",
              name, dim, worst_sum, worst_grad, worst_linear, worst_linear_grad, worst_fd, near_face);
  mpm_test::check_below(worst_sum, sum_limit, "partition of unity");
  mpm_test::check_below(worst_grad, 1e-13, "gradients sum to zero");
  mpm_test::check_below(worst_linear, 1e-12, "linear fields reproduced");
  mpm_test::check_below(worst_linear_grad, 1e-12, "gradients of linear fields reproduced");
  mpm_test::check_below(worst_fd, 1e-6, "gradient equals derivative of the weight");
}

int main()
{
  std::mt19937 rng(42);
  check_family<2, LinearShape>("linear", rng);
  check_family<3, LinearShape>("linear", rng);
  check_family<2, GimpShape>("GIMP", rng);
  check_family<3, GimpShape>("GIMP", rng);
  check_family<2, QuadraticBSplineShape>("quadratic B-spline", rng, true);
  check_family<3, QuadraticBSplineShape>("quadratic B-spline", rng, true);
  check_family<2, CubicBSplineShape>("cubic B-spline", rng, true);
  check_family<3, CubicBSplineShape>("cubic B-spline", rng, true);
  // Domains inside the grid, as GIMP's (where a domain crosses a face the folds give weights
  // down to about -2e-5). Its 1D weights are differences of the B-spline's antiderivative
  // divided by 2 lp, lp down to 0.01 cells here: each loses up to about u / (2 lp) = 1e-14
  // (u = 2.2e-16), the five of a direction up to 5e-14, and the tensor product's sum about
  // as much per direction: the bound 1e-13; measured 1.4e-14.
  check_family<2, CubicBSplineGimpShape>("cubic B-spline GIMP", rng, false, 1e-13);
  check_family<3, CubicBSplineGimpShape>("cubic B-spline GIMP", rng, false, 1e-13);
  check_family<2, TestWideLinearShape>("test wide linear", rng, true);
  check_family<3, TestWideLinearShape>("test wide linear", rng, true);

  // The shape family's test member is linear's function on GIMP's three-node stencil: node by
  // node the same weight and derivative, bit for bit (integer coordinates, where linear's
  // derivative is one-sided, included), and zero on the third node.
  {
    std::uniform_real_distribution<double> u(0.0, 7.0);
    int                                    differ = 0;
    for (int trial = 0; trial < 1000; ++trial)
      {
        const double s = trial < 8 ? double(trial) : (trial < 16 ? trial - 8 + 0.5 : u(rng));
        double       w_l[2], dw_l[2], w_t[3], dw_t[3];
        int          f_l, f_t;
        LinearShape::weights_1d(s, 0.0, f_l, w_l, dw_l);
        TestWideLinearShape::weights_1d(s, 0.0, f_t, w_t, dw_t);
        for (int k = 0; k < 3; ++k)
          {
            const int    j  = f_t + k - f_l;
            const double w  = j == 0 || j == 1 ? w_l[j] : 0.0;
            const double dw = j == 0 || j == 1 ? dw_l[j] : 0.0;
            differ += w_t[k] != w || dw_t[k] != dw;
          }
        differ += f_t != static_cast<int>(std::floor(s + 0.5)) - 1;
      }
    std::printf("test wide linear against linear, 1000 coordinates: %d weights or derivatives differ\n", differ);
    mpm_test::check(differ == 0, "the test member's weights are linear's, node by node");
  }

  // GIMP tends to the linear hat as the particle domain shrinks.
  double w_lin[2], dw_lin[2], w_g[3], dw_g[3];
  int    f_lin, f_g;
  LinearShape::weights_1d(3.3, 0.0, f_lin, w_lin, dw_lin);
  GimpShape::weights_1d(3.3, 1e-9, f_g, w_g, dw_g);
  mpm_test::check_below(std::abs(w_g[f_lin - f_g] - w_lin[0]), 1e-8, "GIMP -> linear for lp -> 0");

  // The B-spline in the interior: 3/4 - r^2 at the nearest node, (3/2 - |r|)^2 / 2 at the
  // others; within half a cell of a face (folded) the linear hats.
  double w_b[3], dw_b[3];
  int    f_b;
  QuadraticBSplineShape::weights_1d(3.3, 0.0, f_b, w_b, dw_b);
  mpm_test::check(f_b == 2, "B-spline stencil starts one node below the nearest", f_b, 2);
  mpm_test::check_below(std::abs(w_b[1] - (0.75 - 0.09)) + std::abs(w_b[0] - 0.5 * 0.2 * 0.2) +
                          std::abs(w_b[2] - 0.5 * 0.8 * 0.8),
                        1e-15, "B-spline weights at s = 3.3");
  stencil_weights_1d<QuadraticBSplineShape>(0.2, 0.0, 5, f_b, w_b, dw_b);
  mpm_test::check_below(std::abs(w_b[0]) + std::abs(w_b[1] - 0.8) + std::abs(w_b[2] - 0.2) +
                          std::abs(dw_b[1] + 1) + std::abs(dw_b[2] - 1),
                        1e-15, "B-spline folded at the lower face: the linear hats");
  stencil_weights_1d<QuadraticBSplineShape>(4.9, 0.0, 5, f_b, w_b, dw_b);
  mpm_test::check_below(std::abs(w_b[2]) + std::abs(w_b[1] - 0.9) + std::abs(w_b[0] - 0.1), 1e-15,
                        "B-spline folded at the upper face: the linear hats");

  // The cubic B-spline in the interior: 2/3 - r^2 + |r|^3 / 2 within a cell of the node,
  // (2 - |r|)^3 / 6 beyond; in the face's cell the ghost node's weight moves to the face
  // node (x2) and its neighbour (x-1).
  auto cubic = [](const double r) {
    const double a = std::abs(r);
    return a < 1 ? 2.0 / 3 - a * a + a * a * a / 2 : a < 2 ? (2 - a) * (2 - a) * (2 - a) / 6 : 0.0;
  };
  double w_c[4], dw_c[4];
  int    f_c;
  CubicBSplineShape::weights_1d(3.3, 0.0, f_c, w_c, dw_c);
  mpm_test::check(f_c == 2, "cubic B-spline stencil starts one node below the point's cell", f_c, 2);
  double cubic_error = 0;
  for (int k = 0; k < 4; ++k)
    cubic_error += std::abs(w_c[k] - cubic(3.3 - (2 + k)));
  mpm_test::check_below(cubic_error, 1e-15, "cubic B-spline weights at s = 3.3");
  stencil_weights_1d<CubicBSplineShape>(0.2, 0.0, 5, f_c, w_c, dw_c);
  const double ghost = cubic(1.2);
  mpm_test::check_below(std::abs(w_c[0]) + std::abs(w_c[1] - (cubic(0.2) + 2 * ghost)) +
                          std::abs(w_c[2] - (cubic(0.8) - ghost)) + std::abs(w_c[3] - cubic(1.8)),
                        1e-15, "cubic B-spline folded at the lower face");
  stencil_weights_1d<CubicBSplineShape>(1.2, 0.0, 5, f_c, w_c, dw_c);
  mpm_test::check_below(std::abs(w_c[0] - cubic(1.2)) + std::abs(w_c[1] - cubic(0.2)), 1e-15,
                        "cubic B-spline not folded beyond the face's cell");
  stencil_weights_1d<CubicBSplineShape>(4.7, 0.0, 5, f_c, w_c, dw_c);
  mpm_test::check_below(std::abs(w_c[3]) + std::abs(w_c[2] - (cubic(0.3) + 2 * cubic(1.3))) +
                          std::abs(w_c[1] - (cubic(0.7) - cubic(1.3))) + std::abs(w_c[0] - cubic(1.7)),
                        1e-15, "cubic B-spline folded at the upper face");

  // The cubic B-spline GIMP: the cubic's mean over [s - lp, s + lp] (midpoint rule with 20,000
  // intervals, error ~1e-10) at interior points, and below lp = 1e-4 cells (where the shape
  // takes the point value instead of the difference quotient) the cubic itself.
  double w_a[5], dw_a[5];
  int    f_a;
  for (const double lp : {0.05, 0.25, 0.49})
    {
      CubicBSplineGimpShape::weights_1d(3.3, lp, f_a, w_a, dw_a);
      double error = 0;
      for (int k = 0; k < 5; ++k)
        {
          const int m    = 20000;
          double    mean = 0;
          for (int q = 0; q < m; ++q)
            mean += cubic(3.3 - lp + (q + 0.5) * 2 * lp / m - (f_a + k)) / m;
          error = std::max(error, std::abs(w_a[k] - mean));
        }
      mpm_test::check_below(error, 1e-9, "cubic B-spline GIMP weights: the cubic's mean over the domain");
    }
  CubicBSplineGimpShape::weights_1d(3.3, 1e-6, f_a, w_a, dw_a);
  mpm_test::check(f_a == 2, "cubic B-spline GIMP stencil starts one node below floor(s - lp)", f_a, 2);
  CubicBSplineShape::weights_1d(3.3, 0.0, f_c, w_c, dw_c);
  double point_error = std::abs(w_a[4]);
  for (int k = 0; k < 4; ++k)
    point_error += std::abs(w_a[k] - w_c[k]);
  mpm_test::check_below(point_error, 1e-12, "cubic B-spline GIMP -> cubic B-spline for lp -> 0");
  return mpm_test::finish("test_shape_functions");
}
