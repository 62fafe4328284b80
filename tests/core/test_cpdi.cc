// CPDI's weights (cpdi.h) at random points with random domains R (stretched, sheared and
// rotated, up to two cells across), 2D and 3D:
// - partition of unity, gradients summing to zero, linear fields and their gradients
//   reproduced, for any domain, its corners moved onto the lattice where they leave it;
// - for an axis-aligned domain inside one cell S_ip and grad S_ip are the hats' exact
//   averages over it, N_i(x_p) and grad N_i(x_p): the linear shape's at x_p;
// - S_ip is the average of the corners' interpolant over the domain: compared with a Gauss
//   quadrature of sum_c N_i(x_c) Phi_c(xi) over the reference cube (and grad S_ip with the
//   divergence theorem: the interpolant's flux through the domain's faces / volume);
// - for an axis-aligned domain inside a cell CPDI equals uGIMP with the same half-lengths.
#include <mpm/core/host_storage.h>
#include <mpm/core/interpolation.h>

#include "check.h"

#include <algorithm>
#include <array>
#include <map>
#include <random>

using namespace mpm;

template <int dim>
using NodeValues = std::map<int, std::pair<double, std::array<double, 3>>>; // node -> (S, grad S)

template <int dim, typename Shape>
NodeValues<dim> stencil_of(const GridView<dim, double> &g, const double *x, const double *domain)
{
  NodeValues<dim> out;
  for_each_stencil_node<dim, Shape>(g, x, domain, [&](const int n, const double N, const double *grad) {
    auto &entry = out[n]; // a CPDI node is visited once per corner whose cell holds it
    entry.first += N;
    for (int d = 0; d < dim; ++d)
      entry.second[d] += grad[d];
  });
  return out;
}

template <int dim>
double node_coordinate(const GridView<dim, double> &g, const int n, const int d)
{
  int rest = n;
  for (int e = 0; e < d; ++e)
    rest /= g.n_cells[e] + 1;
  return g.origin[d] + (rest % (g.n_cells[d] + 1)) * g.h;
}

// R = Q S (I + T): a rotation Q, stretches S of 0.2-1 x reach h and a shear T of up to 0.5.
template <int dim>
void random_domain(std::mt19937 &rng, const double h, const double reach, double R[dim * dim])
{
  std::uniform_real_distribution<double> u(0.0, 1.0);
  double                                 Q[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
  for (int axis = 0; axis < (dim == 2 ? 1 : 3); ++axis) // rotations about z (2D), z, x, y (3D)
    {
      const double a = 2 * M_PI * u(rng), c = std::cos(a), s = std::sin(a);
      const int    i = axis == 1 ? 1 : 0, j = axis == 1 ? 2 : axis == 2 ? 2 : 1;
      for (int r = 0; r < 3; ++r)
        {
          const double qi = Q[r * 3 + i], qj = Q[r * 3 + j];
          Q[r * 3 + i]    = c * qi - s * qj;
          Q[r * 3 + j]    = s * qi + c * qj;
        }
    }
  double stretch[dim], shear[dim * dim];
  for (int d = 0; d < dim; ++d)
    stretch[d] = (0.2 + 0.8 * u(rng)) * reach * h / 2;
  for (int a = 0; a < dim; ++a)
    for (int b = 0; b < dim; ++b)
      shear[a * dim + b] = a == b ? 1 : a < b ? 0.5 * (2 * u(rng) - 1) : 0;
  for (int a = 0; a < dim; ++a)
    for (int b = 0; b < dim; ++b)
      {
        double sum = 0;
        for (int k = 0; k < dim; ++k)
          sum += Q[a * 3 + k] * stretch[k] * shear[k * dim + b];
        R[a * dim + b] = sum;
      }
}

// The linear hat of node n at x.
template <int dim>
double hat(const GridView<dim, double> &g, const int n, const double *x)
{
  double N = 1;
  for (int d = 0; d < dim; ++d)
    {
      const double r = std::abs(x[d] - node_coordinate(g, n, d)) / g.h;
      N *= r < 1 ? 1 - r : 0;
    }
  return N;
}

template <int dim>
void check_cpdi(std::mt19937 &rng)
{
  HostGrid<dim, double> grid;
  const double          lower[3] = {-1.0, 0.5, 2.0};
  const int             cells[3] = {9, 8, 7};
  grid.make_dense(lower, 0.37, cells);
  const GridView<dim, double>            g = grid.view();
  std::uniform_real_distribution<double> u(0.0, 1.0);

  double worst_sum = 0, worst_grad = 0, worst_linear = 0, worst_linear_grad = 0, worst_quadrature = 0,
         worst_flux = 0, worst_in_cell = 0, worst_negative = 0;
  int    clamped = 0;
  for (int trial = 0; trial < 1000; ++trial)
    {
      double R[dim * dim], x[dim];
      random_domain<dim>(rng, g.h, trial % 3 == 0 ? 2.0 : 0.8, R);
      // one in five trials near a face, where corners leave the lattice and are moved onto it
      for (int d = 0; d < dim; ++d)
        x[d] = g.origin[d] + (trial % 5 == 0 ? u(rng) * 0.5 : 2.5 + u(rng) * (g.n_cells[d] - 5)) * g.h;
      bool outside = false;
      for (int c = 0; c < (1 << dim); ++c)
        for (int d = 0; d < dim; ++d)
          {
            double xc = x[d];
            for (int k = 0; k < dim; ++k)
              xc += ((c >> k) & 1 ? 1 : -1) * R[d * dim + k];
            outside = outside || xc < g.origin[d] || xc > g.origin[d] + g.n_cells[d] * g.h;
          }
      clamped += outside;

      const NodeValues<dim> S = stencil_of<dim, CpdiShape>(g, x, R);
      double                sum = 0, grad_sum[dim] = {}, moment[dim] = {}, moment_grad[dim][dim] = {};
      for (const auto &[n, value] : S)
        {
          sum += value.first;
          worst_negative = std::max(worst_negative, -value.first);
          for (int d = 0; d < dim; ++d)
            {
              const double x_n = node_coordinate(g, n, d);
              grad_sum[d] += value.second[d];
              moment[d] += value.first * x_n;
              for (int e = 0; e < dim; ++e)
                moment_grad[d][e] += x_n * value.second[e];
            }
        }
      worst_sum = std::max(worst_sum, std::abs(sum - 1));
      for (int d = 0; d < dim; ++d)
        {
          worst_grad = std::max(worst_grad, std::abs(grad_sum[d]) * g.h);
          if (!outside) // the moved corners no longer average to x_p
            {
              worst_linear = std::max(worst_linear, std::abs(moment[d] - x[d]) / g.h);
              for (int e = 0; e < dim; ++e)
                worst_linear_grad =
                  std::max(worst_linear_grad, std::abs(moment_grad[d][e] - (d == e ? 1.0 : 0.0)));
            }
        }
      if (outside)
        continue;

      // The corners' interpolant I(xi) = sum_c N(x_c) Phi_c(xi) averaged over the reference
      // cube by 3-point Gauss (exact: multilinear), and its gradient's average by the
      // divergence theorem: (1/V) sum over faces of the face-averaged I times the face's
      // area vector, with V = 2^dim |det R| (each face of the parallelepiped is flat).
      const double gauss[3] = {-std::sqrt(0.6), 0, std::sqrt(0.6)}, gauss_w[3] = {5.0 / 9, 8.0 / 9, 5.0 / 9};
      for (const auto &[n, value] : S)
        {
          double corner_N[1 << dim];
          for (int c = 0; c < (1 << dim); ++c)
            {
              double xc[dim];
              for (int d = 0; d < dim; ++d)
                {
                  xc[d] = x[d];
                  for (int k = 0; k < dim; ++k)
                    xc[d] += ((c >> k) & 1 ? 1 : -1) * R[d * dim + k];
                }
              corner_N[c] = hat<dim>(g, n, xc);
            }
          auto interpolant = [&](const double *xi) {
            double I = 0;
            for (int c = 0; c < (1 << dim); ++c)
              {
                double phi = 1;
                for (int k = 0; k < dim; ++k)
                  phi *= 0.5 * (1 + ((c >> k) & 1 ? 1 : -1) * xi[k]);
                I += corner_N[c] * phi;
              }
            return I;
          };
          double mean = 0;
          for (int q = 0; q < (dim == 2 ? 9 : 27); ++q)
            {
              const int    k[3] = {q % 3, q / 3 % 3, q / 9};
              double       xi[dim], weight = 1;
              for (int d = 0; d < dim; ++d)
                {
                  xi[d] = gauss[k[d]];
                  weight *= gauss_w[k[d]] / 2;
                }
              mean += weight * interpolant(xi);
            }
          worst_quadrature = std::max(worst_quadrature, std::abs(mean - value.first));

          // flux: face xi_k = +-1 has area vector +-(cofactor column k) * 2^(dim-1) (its
          // edges 2 r_j, j != k), and the face's mean of I is the mean over the other axes.
          double det, inv_t[dim * dim];
          inverse_transpose<dim>(R, inv_t);
          if constexpr (dim == 2)
            det = R[0] * R[3] - R[1] * R[2];
          else
            det = R[0] * (R[4] * R[8] - R[5] * R[7]) - R[1] * (R[3] * R[8] - R[5] * R[6]) +
                  R[2] * (R[3] * R[7] - R[4] * R[6]);
          const double volume = std::pow(2.0, dim) * std::abs(det);
          double       flux[dim] = {};
          for (int k = 0; k < dim; ++k)
            for (const double side : {-1.0, 1.0})
              {
                double face_mean = 0;
                for (int q = 0; q < (dim == 2 ? 3 : 9); ++q)
                  {
                    double xi[dim], weight = 1;
                    int    other = q;
                    for (int d = 0; d < dim; ++d)
                      if (d == k)
                        xi[d] = side;
                      else
                        {
                          xi[d] = gauss[other % 3];
                          weight *= gauss_w[other % 3] / 2;
                          other /= 3;
                        }
                    face_mean += weight * interpolant(xi);
                  }
                // area vector of the face: (cofactor of R)_{:,k} * 2^(dim-1) * sign(det) * side
                for (int d = 0; d < dim; ++d)
                  flux[d] += face_mean * side * inv_t[d * dim + k] * det * std::pow(2.0, dim - 1) *
                             (det > 0 ? 1 : -1);
              }
          for (int d = 0; d < dim; ++d)
            worst_flux = std::max(worst_flux, std::abs(flux[d] / volume - value.second[d]) * g.h);
        }

      // An axis-aligned domain inside one cell: the hats are multilinear there, so their exact
      // averages are N_i(x_p) and grad N_i(x_p) (a sheared domain's are not: N(x(xi)) is then
      // quadratic in xi, which the corners' interpolant is not).
      double small[dim * dim] = {};
      for (int d = 0; d < dim; ++d)
        small[d * dim + d] = (0.05 + 0.4 * u(rng)) * g.h;
      double centre[dim];
      for (int d = 0; d < dim; ++d)
        centre[d] = g.origin[d] + (std::floor((x[d] - g.origin[d]) / g.h) + 0.5) * g.h;
      const NodeValues<dim> in_cell = stencil_of<dim, CpdiShape>(g, centre, small);
      double                zero[dim] = {};
      const NodeValues<dim> linear  = stencil_of<dim, LinearShape>(g, centre, zero);
      for (const auto &[n, value] : in_cell)
        {
          const auto it = linear.find(n);
          const auto reference = it == linear.end() ? std::make_pair(0.0, std::array<double, 3>{}) : it->second;
          worst_in_cell = std::max(worst_in_cell, std::abs(value.first - reference.first));
          for (int d = 0; d < dim; ++d)
            worst_in_cell = std::max(worst_in_cell, std::abs(value.second[d] - reference.second[d]) * g.h);
        }
    }
  std::printf("CPDI %dD: max |sum S - 1| = %.2e, |sum grad S| h = %.2e, linear %.2e, linear gradient %.2e, "
              "against the quadrature of the corners' interpolant %.2e, its flux %.2e, inside a cell against "
              "linear %.2e, most negative weight %.2e (%d of 1000 domains reach beyond a face)\n",
              dim, worst_sum, worst_grad, worst_linear, worst_linear_grad, worst_quadrature, worst_flux,
              worst_in_cell, worst_negative, clamped);
  mpm_test::check(clamped > 50, "some domains reach beyond the lattice's faces", clamped, 50);
  mpm_test::check_below(worst_sum, 1e-14, "partition of unity");
  mpm_test::check_below(worst_grad, 1e-12, "gradients sum to zero");
  mpm_test::check_below(worst_linear, 1e-12, "linear fields reproduced");
  mpm_test::check_below(worst_linear_grad, 1e-12, "gradients of linear fields reproduced");
  mpm_test::check_below(worst_negative, 0, "weights are non-negative");
  mpm_test::check_below(worst_quadrature, 1e-13, "S is the domain average of the corners' interpolant");
  mpm_test::check_below(worst_flux, 1e-12, "grad S is the domain average of the interpolant's gradient");
  mpm_test::check_below(worst_in_cell, 1e-13, "inside one cell CPDI is the linear hat's exact average");
}

// CPDI2q (2D): random quadrilaterals (a random parallelogram's corners each moved by up to a
// fifth of the domain's size): partition of unity, gradients summing to zero, a linear field
// reproduced as its mean over the quadrilateral (the value at the centroid) and its gradient
// exactly; on a parallelogram CPDI2q's weights are CPDI's.
void check_cpdi2q(std::mt19937 &rng)
{
  HostGrid<2, double> grid;
  const double        lower[2] = {-1.0, 0.5};
  const int           cells[2] = {9, 8};
  grid.make_dense(lower, 0.37, cells);
  const GridView<2, double>              g = grid.view();
  std::uniform_real_distribution<double> u(0.0, 1.0);
  double worst_sum = 0, worst_grad = 0, worst_centroid = 0, worst_linear_grad = 0, worst_parallelogram = 0;
  for (int trial = 0; trial < 1000; ++trial)
    {
      double R[4], x[2], q[8];
      random_domain<2>(rng, g.h, trial % 3 == 0 ? 2.0 : 0.8, R);
      for (int d = 0; d < 2; ++d)
        x[d] = g.origin[d] + (2.5 + u(rng) * (g.n_cells[d] - 5)) * g.h;
      for (int c = 0; c < 4; ++c)
        for (int d = 0; d < 2; ++d)
          q[2 * c + d] = corner_offset<2, CpdiShape>(R, d, c);
      // a parallelogram first: CPDI's weights
      {
        const NodeValues<2> a = stencil_of<2, CpdiShape>(g, x, R), b = stencil_of<2, Cpdi2qShape>(g, x, q);
        for (const auto &[n, value] : a)
          {
            const auto &other = b.at(n);
            worst_parallelogram = std::max({worst_parallelogram, std::abs(value.first - other.first),
                                            std::abs(value.second[0] - other.second[0]) * g.h,
                                            std::abs(value.second[1] - other.second[1]) * g.h});
          }
      }
      const double size = std::sqrt(std::abs(R[0] * R[3] - R[1] * R[2]));
      for (int k = 0; k < 8; ++k)
        q[k] += 0.2 * size * (2 * u(rng) - 1);
      double wf[4], wg[4][2];
      if (!(cpdi2q_corner_factors(q, wf, wg) > 0))
        continue;
      // the centroid by 2 x 2 Gauss points of the isoparametric map
      double centroid[2] = {}, volume = 0;
      for (int k = 0; k < 4; ++k)
        {
          const double xi = (k & 1 ? 1 : -1) / std::sqrt(3.0), eta = (k & 2 ? 1 : -1) / std::sqrt(3.0);
          double       pos[2] = {}, J[4] = {};
          for (int c = 0; c < 4; ++c)
            {
              const double sx = c & 1 ? 1 : -1, sy = c & 2 ? 1 : -1;
              const double phi = 0.25 * (1 + sx * xi) * (1 + sy * eta);
              for (int d = 0; d < 2; ++d)
                {
                  pos[d] += phi * q[2 * c + d];
                  J[2 * d] += 0.25 * sx * (1 + sy * eta) * q[2 * c + d];
                  J[2 * d + 1] += 0.25 * sy * (1 + sx * xi) * q[2 * c + d];
                }
            }
          const double det = J[0] * J[3] - J[1] * J[2];
          volume += det;
          for (int d = 0; d < 2; ++d)
            centroid[d] += det * pos[d];
        }
      const NodeValues<2> S   = stencil_of<2, Cpdi2qShape>(g, x, q);
      double              sum = 0, grad_sum[2] = {}, moment[2] = {}, moment_grad[2][2] = {};
      for (const auto &[n, value] : S)
        {
          sum += value.first;
          for (int d = 0; d < 2; ++d)
            {
              const double x_n = node_coordinate(g, n, d);
              grad_sum[d] += value.second[d];
              moment[d] += value.first * x_n;
              for (int e = 0; e < 2; ++e)
                moment_grad[d][e] += x_n * value.second[e];
            }
        }
      worst_sum = std::max(worst_sum, std::abs(sum - 1));
      for (int d = 0; d < 2; ++d)
        {
          worst_grad     = std::max(worst_grad, std::abs(grad_sum[d]) * g.h);
          worst_centroid = std::max(worst_centroid, std::abs(moment[d] - (x[d] + centroid[d] / volume)) / g.h);
          for (int e = 0; e < 2; ++e)
            worst_linear_grad = std::max(worst_linear_grad, std::abs(moment_grad[d][e] - (d == e ? 1.0 : 0.0)));
        }
    }
  std::printf("CPDI2q: max |sum S - 1| = %.2e, |sum grad S| h = %.2e, linear field against its value at the "
              "centroid %.2e, linear gradient %.2e, parallelogram against CPDI %.2e\n",
              worst_sum, worst_grad, worst_centroid, worst_linear_grad, worst_parallelogram);
  mpm_test::check_below(worst_sum, 1e-14, "CPDI2q: partition of unity");
  mpm_test::check_below(worst_grad, 1e-12, "CPDI2q: gradients sum to zero");
  mpm_test::check_below(worst_centroid, 1e-12, "CPDI2q: a linear field's mean over the quadrilateral");
  mpm_test::check_below(worst_linear_grad, 1e-12, "CPDI2q: gradients of linear fields reproduced");
  mpm_test::check_below(worst_parallelogram, 1e-13, "CPDI2q on a parallelogram = CPDI");
}

int main()
{
  std::mt19937 rng(7);
  check_cpdi<2>(rng);
  check_cpdi<3>(rng);
  check_cpdi2q(rng);
  {
    // A folded quadrilateral (two corners swapped: V <= 0) and a flat CPDI domain (det R = 0):
    // NaN weights, so the run stops with the instability message, never a point without mass.
    const double folded[8] = {-0.1, -0.1, 0.1, 0.1, -0.1, 0.1, 0.1, -0.1};
    double       wf[4], wg[4][2];
    const double V = cpdi2q_corner_factors(folded, wf, wg);
    mpm_test::check(V <= 0 && std::isnan(wf[0]) && std::isnan(wg[0][0]), "CPDI2q: a folded quadrilateral gives NaN");
    const double flat[4] = {0.1, 0.2, 0.05, 0.1}; // columns parallel
    double       inv_t[4];
    inverse_transpose<2>(flat, inv_t);
    mpm_test::check(std::isnan(inv_t[0]), "CPDI: a flat domain gives NaN gradients");
  }

  // An axis-aligned domain inside a cell: uGIMP's weights (both the hat's exact average there).
  HostGrid<2, double> grid;
  const double        lower[2] = {0, 0};
  const int           cells[2] = {6, 6};
  grid.make_dense(lower, 0.5, cells);
  const GridView<2, double> g = grid.view();
  const double              x[2] = {1.37, 2.11}, lp[2] = {0.1, 0.05};
  const double              R[4] = {lp[0], 0, 0, lp[1]};
  const NodeValues<2>       cpdi = stencil_of<2, CpdiShape>(g, x, R);
  const NodeValues<2>       gimp = stencil_of<2, GimpShape>(g, x, lp);
  double                    worst = 0;
  for (const auto &[n, value] : gimp)
    {
      const auto it = cpdi.find(n);
      const auto c  = it == cpdi.end() ? std::make_pair(0.0, std::array<double, 3>{}) : it->second;
      worst         = std::max({worst, std::abs(c.first - value.first), std::abs(c.second[0] - value.second[0]) * g.h,
                                std::abs(c.second[1] - value.second[1]) * g.h});
    }
  std::printf("CPDI against uGIMP, axis-aligned domain inside a cell: %.2e\n", worst);
  mpm_test::check_below(worst, 1e-14, "CPDI = uGIMP for an axis-aligned domain inside a cell");
  return mpm_test::finish("test_cpdi");
}
