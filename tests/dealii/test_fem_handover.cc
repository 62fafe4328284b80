// The FEM hand-over, placement (a) (fem_handover.h), 2D and 3D:
//  - a displacement u = A X that FE_Q(2)^dim represents exactly, on a distorted mesh: every point
//    sits at X + A X of its quadrature point, with F = I + A, volume det(F) JxW, mass rho JxW and
//    strain sym(A), to round-off;
//  - after Simulator::setup the run holds every point's stress and plastic strain as handed over
//    (the quadrature-point field reproduced at the points), to 1e-12 relative;
//  - with a user model that declares two state variables, the run holds their handed-over values
//    at every point, unchanged, also through an FEM file (save_fem_state, then the executable's
//    reader); points without them, or quadrature points that give different numbers of them, are
//    refused;
//  - bad input stops with a message that says what is wrong: a scalar FE, a material_id the map
//    does not name, a point outside the MPM grid, a cell without quadrature-point history, a
//    material with a random field, a displacement vector of the wrong size, the same points handed
//    over twice.
#include "../core/check.h"

#include <mpm/dealii/fem_handover.h>
#include <mpm/dealii/fem_state_file.h>
#include <mpm/dealii/material_library.h>
#include <mpm/dealii/parameters.h>
#include <mpm/dealii/simulator.h>

#include <deal.II/base/function.h>
#include <deal.II/base/mpi.h>
#include <deal.II/base/quadrature_lib.h>
#include <deal.II/fe/fe_q.h>
#include <deal.II/fe/fe_system.h>
#include <deal.II/grid/grid_generator.h>
#include <deal.II/grid/grid_tools.h>
#include <deal.II/grid/tria.h>
#include <deal.II/lac/vector.h>
#include <deal.II/numerics/vector_tools.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <string>

using namespace dealii;
using mpm_test::check;
using mpm_test::throws_naming;
using mpm_test::check_below;

namespace
{
  // Elastic, with two state variables that only the hand-over sets (the run holds them).
  class ElasticWithState : public mpm::UserConstitutiveModel
  {
  public:
    static void declare_parameters(ParameterHandler &) {}
    void        parse_parameters(ParameterHandler &) {}
    std::vector<mpm::StateVariable> state_variables() const override { return {{"void_ratio", 0.7}, {"hardening", 0}}; }
    mpm::LinearElasticParameters<double> elastic_parameters() const override { return {1e7, 0.3}; }
    void update_stress(const mpm::SymTensor<double> &d_eps, const mpm::Mat3<double> &d_spin, bool,
                       mpm::SymTensor<double> &stress, double &, double *) const override
    {
      mpm::linear_elastic_update(elastic_parameters(), d_eps, d_spin, stress);
    }
  };
} // namespace

MPM_REGISTER_CONSTITUTIVE_MODEL(ElasticWithState, "elastic with state", "A test: two state variables.");

namespace
{
  struct History : mpm::QuadraturePointState
  {};

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
  class Linear : public Function<dim>
  {
  public:
    Linear()
      : Function<dim>(dim)
    {}
    double value(const Point<dim> &p, const unsigned int component) const override
    {
      return (gradient_A<dim>() * p)[component];
    }
  };

  template <int dim>
  std::string scene(const bool with_state_variables = false)
  {
    const std::string d3 = dim == 3 ? ", 0" : "", u3 = dim == 3 ? ", 4" : "";
    return "set Dimension = " + std::to_string(dim) +
           "\nsubsection Grid\n set Lower corner = -1, -1" + d3 + "\n set Upper corner = 5, 5" + u3 +
           "\n set Cell size = 0.5\nend\n"
           "subsection Materials\n set Names = soil, rock" + (with_state_variables ? ", clay" : "") + "\nend\n" +
           (with_state_variables ? "subsection Material clay\n set Model = elastic with state\nend\n" : "") +
           "subsection Material soil\n set Model = linear elastic\nend\n"
           "subsection Material rock\n set Model = drucker prager\n subsection drucker prager\n  set Cohesion = 1e4\n"
           " end\n subsection Random field\n  set Parameter = cohesion\n  set Standard deviation = 1e3\n end\nend\n"
           "subsection Material points\n subsection Body 1\n  set Upper corner = 1, 1" + (dim == 3 ? ", 1" : "") +
           "\n end\nend\n"
           "subsection Output\n set Directory = output-fem-handover\n set Output interval = 0\n"
           " set Write particles = false\n set Write grid fields = false\n set Progress interval = 0\nend\n";
  }

  template <int dim>
  void test()
  {
    // A distorted mesh of the box [0, 3]^dim (so that JxW varies from point to point).
    Triangulation<dim> triangulation;
    GridGenerator::subdivided_hyper_cube(triangulation, 3, 0, 3);
    GridTools::distort_random(0.2, triangulation, /*keep_boundary=*/true, /*seed=*/5);
    for (const auto &cell : triangulation.active_cell_iterators())
      cell->set_material_id(cell->center()[0] < 1.5 ? 7 : 8);
    const FESystem<dim> fe(FE_Q<dim>(2), dim);
    DoFHandler<dim>     dof_handler(triangulation);
    dof_handler.distribute_dofs(fe);
    Vector<double> u(dof_handler.n_dofs());
    VectorTools::interpolate(dof_handler, Linear<dim>(), u);

    const QGauss<dim> quadrature(3);
    CellDataStorage<typename Triangulation<dim>::cell_iterator, History> history;
    history.initialize(triangulation.begin_active(), triangulation.end(), quadrature.size());
    double largest_stress = 0;
    for (const auto &cell : triangulation.active_cell_iterators())
      {
        const auto data = history.get_data(cell);
        for (unsigned int q = 0; q < quadrature.size(); ++q)
          {
            for (int c = 0; c < mpm::n_voigt; ++c)
              data[q]->stress[c] = -1e5 * (1 + c) + 1234.5 * cell->center()[0] + 17.0 * q;
            if (dim == 2)
              data[q]->stress[4] = data[q]->stress[5] = 0;
            data[q]->plastic_strain = 0.001 * q;
            largest_stress          = std::max(largest_stress, 6e5);
          }
      }
    const std::map<types::material_id, mpm::HandoverMaterial> materials{{7, {0, 2000}}, {8, {0, 2500}}};
    const mpm::GeneratedBody<dim> body =
      mpm::points_at_quadrature_points(dof_handler, u, quadrature, history, materials);

    // Kinematics against the exact u = A X.
    const Tensor<2, dim> A = gradient_A<dim>();
    Tensor<2, dim>       F = A;
    for (int d = 0; d < dim; ++d)
      F[d][d] += 1;
    FEValues<dim> fe_values(fe, quadrature, update_quadrature_points | update_JxW_values);
    double        position = 0, gradient = 0, volume = 0, mass = 0, strain = 0;
    int           i        = 0;
    for (const auto &cell : dof_handler.active_cell_iterators())
      {
        fe_values.reinit(cell);
        const double rho = cell->material_id() == 7 ? 2000 : 2500;
        for (unsigned int q = 0; q < quadrature.size(); ++q, ++i)
          {
            const Point<dim> X = fe_values.quadrature_point(q);
            const Tensor<1, dim> x = X + A * X;
            for (int d = 0; d < dim; ++d)
              {
                position = std::max(position, std::abs(body.points.position[d][i] - x[d]));
                for (int e = 0; e < dim; ++e)
                  gradient = std::max(gradient, std::abs(body.points.deformation_gradient[d * dim + e][i] - F[d][e]));
              }
            volume = std::max(volume, std::abs(body.points.volume[i] - determinant(F) * fe_values.JxW(q)) /
                                        fe_values.JxW(q));
            mass   = std::max(mass, std::abs(body.points.mass[i] - rho * fe_values.JxW(q)) / (rho * fe_values.JxW(q)));
            strain = std::max(strain, std::abs(body.points.strain[3][i] - 0.5 * (A[0][1] + A[1][0])));
            strain = std::max(strain, std::abs(body.points.strain[0][i] - A[0][0]));
          }
      }
    std::printf("%dD: %d points; largest error of position %.2e m, F %.2e, volume %.2e, mass %.2e, strain %.2e\n",
                dim, i, position, gradient, volume, mass, strain);
    check(i == int(triangulation.n_active_cells() * quadrature.size()), "one point per quadrature point");
    check_below(position, 1e-13, "positions at X + u(X)");
    check_below(gradient, 1e-13, "F = I + grad u");
    check_below(volume, 1e-13, "volume det(F) JxW");
    check_below(mass, 1e-15, "mass rho JxW");
    check_below(strain, 1e-13, "strain sym(grad u)");

    // The run holds the handed-over stresses (engine order: matched by position).
    mpm::Parameters      parameters = mpm::parameters_from_string(scene<dim>());
    mpm::Simulator<dim>  simulator(parameters, MPI_COMM_WORLD);
    simulator.setup({body});
    const mpm::HostPoints<dim, double> held = simulator.points();
    auto key = [](const mpm::HostPoints<dim, double> &p, const int k) {
      std::array<double, dim> x;
      for (int d = 0; d < dim; ++d)
        x[d] = p.position[d][k];
      return x;
    };
    std::vector<std::pair<std::array<double, dim>, int>> given, run;
    for (int k = 0; k < body.points.size(); ++k)
      given.emplace_back(key(body.points, k), k);
    for (int k = 0; k < held.size(); ++k)
      run.emplace_back(key(held, k), k);
    std::sort(given.begin(), given.end());
    std::sort(run.begin(), run.end());
    double stress = given.size() == run.size() ? 0 : 1e300, plastic = 0;
    for (std::size_t k = 0; k < given.size() && k < run.size(); ++k)
      {
        for (int c = 0; c < mpm::n_voigt; ++c)
          stress = std::max(stress, std::abs(held.stress[c][run[k].second] - body.points.stress[c][given[k].second]));
        plastic = std::max(plastic, std::abs(held.plastic_strain[run[k].second] -
                                             body.points.plastic_strain[given[k].second]));
      }
    std::printf("%dD: stress held by the run against the quadrature points: %.2e relative; plastic strain %.2e\n",
                dim, stress / largest_stress, plastic);
    check_below(stress / largest_stress, 1e-12, "the quadrature-point stress reproduced at the points");
    check_below(plastic, 1e-15, "the plastic strain handed over");

    // State variables of a user model: handed over with the points, held by the run unchanged.
    {
      for (const auto &cell : triangulation.active_cell_iterators())
        for (unsigned int q = 0; q < quadrature.size(); ++q)
          history.get_data(cell)[q]->state_variables = {0.55 + 0.01 * cell->center()[0] + 1e-4 * q,
                                                        -3e-3 * cell->center()[1] * (q + 1)};
      mpm::GeneratedBody<dim> clay = mpm::points_at_quadrature_points(dof_handler, u, quadrature, history, materials);
      std::fill(clay.points.material.begin(), clay.points.material.end(), 2);
      mpm::Simulator<dim> s(mpm::parameters_from_string(scene<dim>(true)), MPI_COMM_WORLD);
      s.setup({clay});
      const mpm::HostPoints<dim, double> in_run = s.points();
      std::vector<std::pair<std::array<double, dim>, int>> placed;
      for (int k = 0; k < in_run.size(); ++k)
        placed.emplace_back(key(in_run, k), k);
      std::sort(placed.begin(), placed.end());
      double state = in_run.n_state_variables() == 2 && placed.size() == given.size() ? 0 : 1e300;
      for (std::size_t k = 0; state == 0 && k < given.size(); ++k)
        for (int v = 0; v < 2; ++v)
          state = std::max(state, std::abs(in_run.state_variables[v][placed[k].second] -
                                           clay.points.state_variables[v][given[k].second]));
      std::printf("%dD: state variables held by the run against the quadrature points: %.2e\n", dim, state);
      check(state == 0, "two state variables of a user model handed over exactly");

      check(throws_naming([&]() {
              mpm::Simulator<dim> r(mpm::parameters_from_string(scene<dim>(true)), MPI_COMM_WORLD);
              r.setup({body});
            },
                          "carry 0 state variable(s), but the run's material models declare 2 (void_ratio, hardening)"),
            "points without the run's state variables are refused, naming them");
      // The same state through a file (save_fem_state, then the executable's reader with
      // Initial state/Source = FEM file): the same points, state variables included.
      {
        const std::string file = "fem-handover-" + std::to_string(dim) + "d.fem-state";
        mpm::save_fem_state(file, dof_handler, u, quadrature, history);
        const mpm::Parameters from_file = mpm::parameters_from_string(
          scene<dim>(true) + "subsection Initial state\n set Source = FEM file\n set FEM file = " + file +
          "\n set Materials = 7: clay, 2000; 8: clay, 2500\nend\n");
        const std::vector<mpm::GeneratedBody<dim>> read = mpm::load_fem_state_points<dim>(from_file, MPI_COMM_WORLD);
        const mpm::HostPoints<dim, double>        &r    = read.at(0).points;
        std::vector<std::pair<std::array<double, dim>, int>> loaded;
        for (int k = 0; k < r.size(); ++k)
          loaded.emplace_back(key(r, k), k);
        std::sort(loaded.begin(), loaded.end());
        double difference = r.n_state_variables() == 2 && loaded.size() == given.size() ? 0 : 1e300;
        for (std::size_t k = 0; difference == 0 && k < given.size(); ++k)
          {
            const int a = loaded[k].second, b = given[k].second;
            for (int d = 0; d < dim; ++d)
              difference = std::max(difference, std::abs(r.position[d][a] - clay.points.position[d][b]));
            for (int c = 0; c < mpm::n_voigt; ++c)
              difference = std::max(difference, std::abs(r.stress[c][a] - clay.points.stress[c][b]) / largest_stress);
            for (int v = 0; v < 2; ++v)
              difference = std::max(difference, std::abs(r.state_variables[v][a] - clay.points.state_variables[v][b]));
            difference = std::max(difference, std::abs(r.volume[a] - clay.points.volume[b]) / clay.points.volume[b]);
            difference = std::max(difference, r.material[a] == 2 ? 0.0 : 1e300);
          }
        std::printf("%dD: FEM file against the API: largest difference %.2e (positions, stresses, state variables, "
                    "volumes)\n",
                    dim, difference);
        check_below(difference, 1e-13, "the FEM file gives the API's points, state variables included");
      }

      history.get_data(triangulation.last_active())[1]->state_variables = {0.5};
      check(throws_naming([&]() { mpm::points_at_quadrature_points(dof_handler, u, quadrature, history, materials); },
                          "gives 1 state variable(s), the first quadrature point 2"),
            "quadrature points with different numbers of state variables are refused");
      for (const auto &cell : triangulation.active_cell_iterators())
        for (unsigned int q = 0; q < quadrature.size(); ++q)
          history.get_data(cell)[q]->state_variables.clear();
    }

    // Bad input.
    {
      const FE_Q<dim> scalar(1);
      DoFHandler<dim> scalar_dofs(triangulation);
      scalar_dofs.distribute_dofs(scalar);
      Vector<double> s(scalar_dofs.n_dofs());
      check(throws_naming([&]() { mpm::points_at_quadrature_points(scalar_dofs, s, quadrature, history, materials); },
                          "vector component(s); the displacement needs"),
            "a scalar FE is refused");
    }
    check(throws_naming(
            [&]() {
              mpm::points_at_quadrature_points(dof_handler, u, quadrature, history, {{7, {0, 2000}}});
            },
            "has material_id 8, which the map of materials"),
          "an unknown material_id is refused");
    check(throws_naming([&]() { mpm::points_at_quadrature_points(dof_handler, Vector<double>(3), quadrature, history, materials); },
                        "the displacement vector has 3 entries"),
          "a displacement of the wrong size is refused");
    {
      CellDataStorage<typename Triangulation<dim>::cell_iterator, History> partial;
      partial.initialize(triangulation.begin_active(), triangulation.begin_active(), quadrature.size());
      check(throws_naming([&]() { mpm::points_at_quadrature_points(dof_handler, u, quadrature, partial, materials); },
                          "holds no state"),
            "a cell without history is refused");
    }
    {
      mpm::GeneratedBody<dim> outside = body;
      outside.points.position[0][3]   = 6;
      mpm::Simulator<dim> s(mpm::parameters_from_string(scene<dim>()), MPI_COMM_WORLD);
      check(throws_naming([&]() { s.setup({outside}); }, "lies outside the MPM grid"),
            "a point outside the MPM grid is refused");
    }
    {
      mpm::GeneratedBody<dim> rock = body;
      std::fill(rock.points.material.begin(), rock.points.material.end(), 1);
      mpm::Simulator<dim> s(mpm::parameters_from_string(scene<dim>()), MPI_COMM_WORLD);
      check(throws_naming([&]() { s.setup({rock}); }, "has a random field"),
            "a material with a random field is refused");
    }
    {
      mpm::GeneratedBody<dim> unknown = body;
      unknown.points.material[0]      = 5;
      mpm::Simulator<dim> s(mpm::parameters_from_string(scene<dim>()), MPI_COMM_WORLD);
      check(throws_naming([&]() { s.setup({unknown}); }, "has material index 5, but Materials/Names declares 2"),
            "an MPM material index out of range is refused");
    }
    {
      mpm::Simulator<dim> s(mpm::parameters_from_string(scene<dim>()), MPI_COMM_WORLD);
      check(throws_naming([&]() { s.setup({body, body}); }, "two points handed over at the same position"),
            "the same cells handed over twice (a serial mesh on every rank) are refused");
    }
  }
} // namespace

int main(int argc, char **argv)
{
  Utilities::MPI::MPI_InitFinalize mpi(argc, argv, 1);
  try
    {
      test<2>();
      test<3>();
    }
  catch (const std::exception &e)
    {
      std::printf("exception: %s\n", e.what());
      return 1;
    }
  return mpm_test::finish("test_fem_handover");
}
