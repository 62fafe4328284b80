// The FEM hand-over, placement (b) (fem_handover_lattice.h): points on the MPM lattice.
//  - kinematics, 2D and 3D: a displacement u = A X + b (exact in FE_Q(2)^dim) on a distorted mesh
//    of the unit box. The points are exactly the lattice points inside the deformed box (counted
//    independently), with F = I + A, volume (h/n)^dim and mass rho (h/n)^dim / det F to round-off;
//  - a linear stress field, and two linear state variables of a user model, are reproduced at the
//    points by the projection of degree 2, to 1e-11 of their size (the inverse of the deformed
//    mapping is Newton's, to about 1e-12);
//  - a smooth stress field given at the Gauss points converges at the points at the projection's
//    rate k + 1 under refinement of the FEM mesh (k = 1 with Q1 and 2x2 Gauss, k = 2 with Q2 and
//    3x3 Gauss, 2D; k = 1 in 3D): the observed rates between the two finest meshes must lie within
//    0.25 of k + 1;
//  - bad input stops with a message: a quadrature too coarse for the projection degree, one with
//    enough points that cannot determine it (all on a line), a material_id the map does not name.
#include "../core/check.h"

#include <mpm/dealii/fem_handover_lattice.h>

#include <deal.II/base/function.h>
#include <deal.II/base/mpi.h>
#include <deal.II/base/quadrature_lib.h>
#include <deal.II/fe/fe_q.h>
#include <deal.II/fe/fe_system.h>
#include <deal.II/fe/fe_values.h>
#include <deal.II/grid/grid_generator.h>
#include <deal.II/grid/grid_tools.h>
#include <deal.II/grid/tria.h>
#include <deal.II/lac/vector.h>
#include <deal.II/numerics/vector_tools.h>

#include <cmath>
#include <cstdio>
#include <functional>
#include <string>

using namespace dealii;
using mpm_test::check;
using mpm_test::throws_naming;
using mpm_test::check_below;

namespace
{
  template <int dim>
  Tensor<2, dim> gradient_A()
  {
    Tensor<2, dim> A;
    for (int d = 0; d < dim; ++d)
      for (int e = 0; e < dim; ++e)
        A[d][e] = 0.01 * (1 + d) - 0.004 * e + (d == e ? -0.03 : 0.0);
    return A;
  }

  template <int dim>
  class Affine : public Function<dim>
  {
  public:
    Affine()
      : Function<dim>(dim)
    {}
    double value(const Point<dim> &p, const unsigned int component) const override
    {
      return (gradient_A<dim>() * p)[component] + 0.013 * (component + 1);
    }
  };

  // The unit box, n cells per direction, interior vertices moved (the mesh is not the lattice).
  template <int dim>
  void unit_box(Triangulation<dim> &tria, const unsigned int n_cells, const bool distort)
  {
    GridGenerator::subdivided_hyper_cube(tria, n_cells, 0, 1);
    if (distort)
      GridTools::transform(
        [](const Point<dim> &p) {
          Point<dim> q = p;
          for (int d = 0; d < dim; ++d)
            q[d] += 0.04 * std::sin(M_PI * p[d]) * std::sin(2 * M_PI * p[(d + 1) % dim]);
          return q;
        },
        tria);
  }

  using StressField = std::function<double(const Point<3> &, int)>;

  // The state function: the stress field evaluated at each quadrature point's position.
  template <int dim>
  mpm::QuadraturePointStateFunction<dim> state_of(const Quadrature<dim> &quadrature, const StressField &sigma)
  {
    return [&quadrature, sigma](const typename DoFHandler<dim>::active_cell_iterator &cell, const unsigned int q) {
      FEValues<dim> fe_values(cell->get_fe(), quadrature, update_quadrature_points);
      fe_values.reinit(cell);
      Point<3> x;
      for (int d = 0; d < dim; ++d)
        x[d] = fe_values.quadrature_point(q)[d];
      mpm::QuadraturePointState s;
      for (int c = 0; c < mpm::n_voigt; ++c)
        s.stress[c] = sigma(x, c);
      s.plastic_strain = sigma(x, 0) * 1e-6;
      // Two state variables of a user model (a void ratio, a hardening variable), from the same field.
      s.state_variables = {0.6 + sigma(x, 0) * 1e-7, -sigma(x, 1) * 1e-4};
      return s;
    };
  }

  template <int dim>
  mpm::LatticeHandover<dim> lattice(const int degree)
  {
    mpm::LatticeHandover<dim> l;
    for (int d = 0; d < dim; ++d)
      l.origin[d] = -0.5;
    l.cell_size                 = 0.125;
    l.points_per_cell_direction = 2;
    l.projection_degree         = degree;
    return l;
  }

  template <int dim>
  void kinematics()
  {
    Triangulation<dim> tria;
    unit_box(tria, 4, true);
    const FESystem<dim> fe(FE_Q<dim>(2), dim);
    DoFHandler<dim>     dof_handler(tria);
    dof_handler.distribute_dofs(fe);
    Vector<double> u(dof_handler.n_dofs());
    VectorTools::interpolate(MappingQ<dim>(2), dof_handler, Affine<dim>(), u);
    const QGauss<dim> quadrature(3);
    const StressField linear = [](const Point<3> &x, const int c) { return 1e3 * (c + 1) * (1 + x[0] - 2 * x[1] + x[2]); };
    const double      rho    = 1800;
    const auto        l      = lattice<dim>(2);
    const mpm::GeneratedBody<dim> body =
      mpm::points_on_lattice(dof_handler, u, quadrature, state_of<dim>(quadrature, linear), {{0, {0, rho}}}, l);
    const mpm::HostPoints<dim, double> &p = body.points;

    // The lattice points inside the deformed box x = (I + A) X + b, X in [0, 1]^dim, counted here.
    Tensor<2, dim> F = gradient_A<dim>();
    for (int d = 0; d < dim; ++d)
      F[d][d] += 1;
    const Tensor<2, dim> F_inverse = invert(F);
    Tensor<1, dim>       b;
    for (int d = 0; d < dim; ++d)
      b[d] = 0.013 * (d + 1);
    const double dx = l.cell_size / l.points_per_cell_direction;
    long         expected = 0;
    const long   n_lattice = static_cast<long>(std::round(2.5 / dx));
    for (long k = 0; k < std::pow(n_lattice, dim); ++k)
      {
        Point<dim> x;
        long       rest = k;
        for (int d = 0; d < dim; ++d, rest /= n_lattice)
          x[d] = l.origin[d] + (rest % n_lattice + 0.5) * dx;
        const Tensor<1, dim> X      = F_inverse * (x - Point<dim>(b));
        bool                 inside = true;
        for (int d = 0; d < dim; ++d)
          inside = inside && X[d] >= -1e-12 && X[d] <= 1 + 1e-12;
        expected += inside;
      }

    // The field's size: (c + 1) 1e3 (1 + x - 2 y + z) reaches 4 * 6e3 on the deformed box.
    const double linear_scale = 2.4e4;
    double worst_F = 0, worst_volume = 0, worst_mass = 0, worst_stress = 0, worst_lattice = 0, worst_state = 0;
    const double J = determinant(F), V = std::pow(dx, dim);
    for (int i = 0; i < p.size(); ++i)
      {
        Point<3> x3;
        for (int d = 0; d < dim; ++d)
          {
            x3[d]     = p.position[d][i];
            const double k = (p.position[d][i] - l.origin[d]) / dx - 0.5;
            worst_lattice = std::max(worst_lattice, std::abs(k - std::round(k)));
            for (int e = 0; e < dim; ++e)
              worst_F = std::max(worst_F, std::abs(p.deformation_gradient[d * dim + e][i] - F[d][e]));
          }
        worst_volume = std::max(worst_volume, std::abs(p.volume[i] - V) / V);
        worst_mass   = std::max(worst_mass, std::abs(p.mass[i] - rho * V / J) / (rho * V / J));
        // The stress was given at the quadrature points' reference positions X: compare there.
        Point<dim> x;
        for (int d = 0; d < dim; ++d)
          x[d] = p.position[d][i];
        const Tensor<1, dim> X = F_inverse * (x - Point<dim>(b));
        Point<3>             X3;
        for (int d = 0; d < dim; ++d)
          X3[d] = X[d];
        for (int c = 0; c < mpm::n_voigt; ++c)
          if (dim == 3 || c < 4)
            worst_stress = std::max(worst_stress, std::abs(p.stress[c][i] - linear(X3, c)) / linear_scale);
        if (p.n_state_variables() == 2)
          worst_state = std::max({worst_state, std::abs(p.state_variables[0][i] - (0.6 + linear(X3, 0) * 1e-7)),
                                  std::abs(p.state_variables[1][i] + linear(X3, 1) * 1e-4) / (linear_scale * 1e-4)});
        else
          worst_state = 1e300;
      }
    std::printf("%dD lattice hand-over of u = A X + b: %d points (%ld lattice points inside the deformed box); "
                "F %.2e, volume %.2e, mass %.2e, stress %.2e, state variables %.2e, off-lattice %.2e\n",
                dim, p.size(), expected, worst_F, worst_volume, worst_mass, worst_stress, worst_state, worst_lattice);
    check(p.size() == expected, "the points are the lattice points inside the deformed body", p.size(), expected);
    check_below(worst_F, 1e-12, "F = I + A at every point");
    check_below(worst_volume, 1e-12, "volume (h/n)^dim");
    check_below(worst_mass, 1e-12, "mass rho (h/n)^dim / det F");
    // Round-off of the local projection and of Newton's inversion of the deformed mapping.
    check_below(worst_stress, 1e-11, "a linear stress field reproduced by the projection of degree 2");
    check_below(worst_state, 1e-11, "two linear state variables reproduced by the same projection");
    check_below(worst_lattice, 1e-9, "positions on the lattice");
  }

  // Largest error at the points of a smooth stress field given at the Gauss points, on a mesh of
  // n_cells per direction, FE degree and projection degree k, no displacement.
  template <int dim>
  double projection_error(const unsigned int n_cells, const unsigned int k)
  {
    Triangulation<dim> tria;
    unit_box(tria, n_cells, true);
    const FESystem<dim> fe(FE_Q<dim>(k), dim);
    DoFHandler<dim>     dof_handler(tria);
    dof_handler.distribute_dofs(fe);
    const Vector<double> u(dof_handler.n_dofs());
    const QGauss<dim>    quadrature(k + 1);
    const StressField    smooth = [](const Point<3> &x, const int c) {
      return std::sin(2 * x[0] + 0.3 * c) * std::cos(1.5 * x[1] - 0.2 * c) * std::exp(0.5 * x[2]);
    };
    const mpm::GeneratedBody<dim> body =
      mpm::points_on_lattice(dof_handler, u, quadrature, state_of<dim>(quadrature, smooth), {{0, {0, 1000}}},
                             lattice<dim>(k));
    double worst = 0;
    for (int i = 0; i < body.points.size(); ++i)
      {
        Point<3> x;
        for (int d = 0; d < dim; ++d)
          x[d] = body.points.position[d][i];
        for (int c = 0; c < (dim == 3 ? mpm::n_voigt : 4); ++c)
          worst = std::max(worst, std::abs(body.points.stress[c][i] - smooth(x, c)));
      }
    return worst;
  }

  template <int dim>
  void convergence(const unsigned int k, const std::vector<unsigned int> &meshes)
  {
    std::vector<double> errors;
    for (const unsigned int n : meshes)
      errors.push_back(projection_error<dim>(n, k));
    std::printf("%dD projection of degree %u (FE_Q(%u), QGauss(%u)):", dim, k, k, k + 1);
    for (unsigned int m = 0; m < meshes.size(); ++m)
      std::printf("  %u cells: %.3e%s", meshes[m], errors[m],
                  m > 0 ? (" (rate " + std::to_string(std::log2(errors[m - 1] / errors[m])) + ")").c_str() : "");
    std::printf("\n");
    const double rate = std::log2(errors[errors.size() - 2] / errors.back());
    check(std::abs(rate - (k + 1)) < 0.25, "the projection converges at its order k + 1", rate, k + 1.0);
  }

} // namespace

int main(int argc, char **argv)
{
  Utilities::MPI::MPI_InitFinalize mpi(argc, argv, 1);
  try
    {
      kinematics<2>();
      kinematics<3>();
      convergence<2>(1, {4, 8, 16, 32});
      convergence<2>(2, {4, 8, 16, 32});
      convergence<3>(1, {2, 4, 8});

      Triangulation<2> tria;
      unit_box(tria, 4, false);
      const FESystem<2> fe(FE_Q<2>(2), 2);
      DoFHandler<2>     dof_handler(tria);
      dof_handler.distribute_dofs(fe);
      const Vector<double> u(dof_handler.n_dofs());
      const QGauss<2>      coarse(2), fine(3);
      const StressField    zero = [](const Point<3> &, int) { return 0.0; };
      check(throws_naming(
              [&]() {
                mpm::points_on_lattice(dof_handler, u, coarse, state_of<2>(coarse, zero), {{0, {0, 1000}}},
                                       lattice<2>(2));
              },
              "needs at least 9 quadrature points per cell (3 per direction); the quadrature has 4"),
            "a quadrature too coarse for the projection degree is refused");
      // Nine points on one line x = 1/2: as many as degree 2 needs, but x is not resolved.
      std::vector<Point<2>> on_a_line;
      for (unsigned int q = 0; q < 9; ++q)
        on_a_line.emplace_back(0.5, (q + 0.5) / 9);
      const Quadrature<2> line(on_a_line, std::vector<double>(9, 1.0 / 9));
      check(throws_naming(
              [&]() {
                mpm::points_on_lattice(dof_handler, u, line, state_of<2>(line, zero), {{0, {0, 1000}}}, lattice<2>(2));
              },
              "its mass matrix is singular"),
            "a quadrature that cannot determine the projection is refused");
      check(throws_naming(
              [&]() {
                mpm::points_on_lattice(dof_handler, u, fine, state_of<2>(fine, zero), {{3, {0, 1000}}}, lattice<2>(2));
              },
              "has material_id 0, which the map of materials"),
            "a material_id the map does not name is refused");
    }
  catch (const std::exception &e)
    {
      std::printf("exception: %s\n", e.what());
      return 1;
    }
  return mpm_test::finish("test_fem_handover_lattice");
}
