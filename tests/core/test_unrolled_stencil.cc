// The device's form of the stencil loop (interpolation.h: unrolled, and without a check per
// node where the lattice is dense and the stencil inside it), compiled here on the host with
// -DMPM_UNROLL_STENCIL, against the host's HostStencil: the same nodes in the same order, N and
// grad N equal to round-off (their products come in another order), for every tensor-product
// shape, 2D and 3D, on three numberings of the nodes:
// - the whole lattice without a table (interior points take the unchecked loop, points near
//   a face the checked one);
// - a box of the lattice without a table (stencils that leave the box are checked);
// - a table with absent nodes (always checked).
// Where the whole stencil is present, the weights of the unrolled form reproduce linear
// fields: sum N = 1, sum grad N = 0, sum N x_i = x_p, sum x_i (x) grad N = I.
#include <mpm/core/cubic_bspline_gimp.h>
#include <mpm/core/interpolation.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "check.h"

#if !defined(MPM_UNROLL_STENCIL)
#  error "test_unrolled_stencil must be compiled with -DMPM_UNROLL_STENCIL (tests/core/CMakeLists.txt)"
#endif

using namespace mpm;
using mpm_test::check;
using mpm_test::check_below;

namespace
{
  template <int dim>
  struct Visit
  {
    int    node;
    double N, grad[dim];
  };

  enum class Numbering
  {
    lattice,
    box,
    table
  };

  template <int dim, typename Shape>
  constexpr int stencil_size()
  {
    return dim == 2 ? Shape::n_per_direction * Shape::n_per_direction :
                      Shape::n_per_direction * Shape::n_per_direction * Shape::n_per_direction;
  }

  template <int dim, typename Shape>
  void compare(const Numbering numbering, const char *label)
  {
    constexpr int n_cells_per_axis = 24;
    const double  h                = 0.25;
    GridView<dim, double> g{};
    for (int d = 0; d < dim; ++d)
      {
        g.origin[d]  = -1.0 + 0.5 * d;
        g.n_cells[d] = n_cells_per_axis + d; // unequal axes catch a swapped stride
      }
    g.h = h;
    g.box_is_lattice();
    std::vector<int> table;
    if (numbering == Numbering::box)
      for (int d = 0; d < dim; ++d)
        {
          g.box_lower[d] = 2 + d;
          g.box_nodes[d] = g.n_cells[d] + 1 - g.box_lower[d] - 3;
        }
    if (numbering == Numbering::table)
      {
        long n_lattice = 1;
        for (int d = 0; d < dim; ++d)
          n_lattice *= g.n_cells[d] + 1;
        std::mt19937 random(7);
        table.resize(n_lattice);
        int next = 0;
        for (long l = 0; l < n_lattice; ++l) // about one node in five absent, the others numbered
          table[l] = random() % 5 == 0 ? -1 : next++;
        g.lattice_to_node = table.data();
      }

    std::mt19937                           random(11);
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    int    n_checked_points = 0, n_whole = 0;
    long   n_visits         = 0;
    double worst_N = 0, worst_grad = 0, worst_unity = 0, worst_gradient_sum = 0, worst_linear = 0,
           worst_identity = 0;
    bool   same_nodes = true;
    for (int point = 0; point < 4000; ++point)
      {
        double x[dim], half_length[dim];
        for (int d = 0; d < dim; ++d)
          {
            x[d]           = g.origin[d] + unit(random) * g.n_cells[d] * h;
            half_length[d] = (0.1 + 0.4 * unit(random)) * h;
          }
        std::vector<Visit<dim>> unrolled, host;
        for_each_stencil_node<dim, Shape>(g, x, half_length, [&](const int node, const double N, const double *grad) {
          Visit<dim> v{node, N, {}};
          std::copy(grad, grad + dim, v.grad);
          unrolled.push_back(v);
        });
        HostStencil<dim, Shape, double>(g, x, half_length).for_each(g, [&](const int node, const double N,
                                                                          const double *grad) {
          Visit<dim> v{node, N, {}};
          std::copy(grad, grad + dim, v.grad);
          host.push_back(v);
        });
        ++n_checked_points;
        n_visits += static_cast<long>(host.size());
        if (unrolled.size() != host.size())
          {
            same_nodes = false;
            continue;
          }
        for (std::size_t k = 0; k < host.size(); ++k)
          {
            same_nodes = same_nodes && unrolled[k].node == host[k].node;
            worst_N    = std::max(worst_N, std::fabs(unrolled[k].N - host[k].N));
            for (int d = 0; d < dim; ++d)
              worst_grad = std::max(worst_grad, std::fabs(unrolled[k].grad[d] - host[k].grad[d]) * h);
          }

        // Linear fields, where no node of the stencil is missing (on the lattice's numbering
        // only: the others number nodes in their own way).
        const int stencil_nodes = stencil_size<dim, Shape>();
        bool inside = true;
        for (int d = 0; d < dim; ++d)
          {
            const double s = (x[d] - g.origin[d]) / h;
            inside         = inside && s > 3 && s < g.n_cells[d] - 3; // clear of every shape's reach
          }
        if (numbering != Numbering::lattice || !inside || static_cast<int>(unrolled.size()) != stencil_nodes)
          continue;
        ++n_whole;
        double unity = 0, gradient_sum[dim] = {}, linear[dim] = {}, identity[dim][dim] = {};
        for (const Visit<dim> &v : unrolled)
          {
            int idx[dim];
            lattice_node_coordinates<dim>(g.n_cells, v.node, idx); // this numbering is the lattice's
            unity += v.N;
            for (int d = 0; d < dim; ++d)
              {
                const double x_node = g.origin[d] + h * idx[d];
                gradient_sum[d] += v.grad[d];
                linear[d] += v.N * (x_node - x[d]);
                for (int e = 0; e < dim; ++e)
                  identity[d][e] += (x_node - x[d]) * v.grad[e];
              }
          }
        worst_unity = std::max(worst_unity, std::fabs(unity - 1));
        for (int d = 0; d < dim; ++d)
          {
            worst_gradient_sum = std::max(worst_gradient_sum, std::fabs(gradient_sum[d]) * h);
            worst_linear       = std::max(worst_linear, std::fabs(linear[d]) / h);
            for (int e = 0; e < dim; ++e)
              worst_identity = std::max(worst_identity, std::fabs(identity[d][e] - (d == e ? 1.0 : 0.0)));
          }
      }

    std::printf("%-26s %dD %-7s: %d points (%d whole stencils): |dN| %.1e, |d grad N| h %.1e; sum N - 1 %.1e, "
                "sum grad N h %.1e, sum N (x_i - x_p) / h %.1e, sum (x_i - x_p) grad N - I %.1e\n",
                label, dim, numbering == Numbering::lattice ? "lattice" : numbering == Numbering::box ? "box" : "table",
                n_checked_points, n_whole, worst_N, worst_grad, worst_unity, worst_gradient_sum, worst_linear,
                worst_identity);
    // Most stencils keep most of their nodes on every numbering (a table absent a fifth of them).
    check(n_visits > 4000L * stencil_size<dim, Shape>() / 3, "nodes visited", static_cast<double>(n_visits),
          4000.0 * stencil_size<dim, Shape>() / 3);
    check(same_nodes, "the unrolled form visits the host form's nodes in its order");
    check_below(worst_N, 1e-14, "N: unrolled against host");
    check_below(worst_grad, 1e-13, "grad N h: unrolled against host");
    if (numbering == Numbering::lattice)
      {
        check(n_whole > 1000, "enough interior points", n_whole, 1000);
        check_below(worst_unity, 1e-14, "sum N = 1");
        check_below(worst_gradient_sum, 1e-13, "sum grad N = 0");
        check_below(worst_linear, 1e-14, "sum N x_i = x_p");
        check_below(worst_identity, 1e-13, "sum x_i (x) grad N = I");
      }
  }

  template <int dim, typename Shape>
  void compare_numberings(const char *label)
  {
    compare<dim, Shape>(Numbering::lattice, label);
    compare<dim, Shape>(Numbering::box, label);
    compare<dim, Shape>(Numbering::table, label);
  }

  template <int dim>
  void compare_shapes()
  {
    compare_numberings<dim, LinearShape>("linear");
    compare_numberings<dim, GimpShape>("GIMP");
    compare_numberings<dim, QuadraticBSplineShape>("quadratic B-spline");
    compare_numberings<dim, CubicBSplineShape>("cubic B-spline");
    compare_numberings<dim, CubicBSplineGimpShape>("cubic B-spline GIMP");
  }
} // namespace

int main()
{
  compare_shapes<2>();
  compare_shapes<3>();
  return mpm_test::finish("test_unrolled_stencil");
}
