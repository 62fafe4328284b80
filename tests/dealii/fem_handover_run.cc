// A hand-over from a distributed FEM (parallel::distributed::Triangulation, FE_Q(2)^dim, a ghosted
// distributed displacement) stepped 100 steps by the MPM, writing its particle tables into the
// folder given as argument. Run on 1 and 2 ranks by ctest, whose compare_np.py asserts the
// results agree point by point (each rank hands over its own cells' points; setup gathers them).
// A second argument "lattice" hands over with placement (b), 2^dim points per MPM cell.
// "fem_handover_run --save FILE" writes the FEM state instead (fem_state_file.h), for the
// executable's Initial state/Source = FEM file. A first argument --3d runs the 3D scene (the
// 2D one extruded 1 m in y, z vertical).
#include <mpm/dealii/fem_handover.h>
#include <mpm/dealii/fem_handover_lattice.h>
#include <mpm/dealii/fem_state_file.h>
#include <mpm/dealii/parameters.h>
#include <mpm/dealii/simulator.h>

#include <deal.II/base/function.h>
#include <deal.II/base/mpi.h>
#include <deal.II/base/quadrature_lib.h>
#include <deal.II/distributed/tria.h>
#include <deal.II/dofs/dof_tools.h>
#include <deal.II/fe/fe_q.h>
#include <deal.II/fe/fe_system.h>
#include <deal.II/grid/grid_generator.h>
#include <deal.II/lac/la_parallel_vector.h>
#include <deal.II/numerics/vector_tools.h>

#include <iostream>
#include <string>
#include <vector>

using namespace dealii;

namespace
{
  // A smooth small displacement (not linear: the FE's interpolation of it is what is handed over);
  // z (y in 2D) is vertical.
  template <int dim>
  class Displacement : public Function<dim>
  {
  public:
    Displacement()
      : Function<dim>(dim)
    {}
    double value(const Point<dim> &p, const unsigned int c) const override
    {
      const double z = p[dim - 1];
      if (c == 0)
        return 0.01 * std::sin(p[0]) * z;
      if (c == dim - 1)
        return -0.02 * z * (2 - 0.1 * p[0]);
      return 0.005 * p[1] * z; // y in 3D
    }
  };

  template <int dim>
  int run(const std::vector<std::string> &args)
  {
    const bool save = args.size() == 2 && args[0] == "--save";
    AssertThrow(args.size() == 1 || (args.size() == 2 && (save || args[1] == "lattice")),
                ExcMessage("usage: fem_handover_run [--3d] OUTPUT_DIRECTORY [lattice] | [--3d] --save FILE"));
    parallel::distributed::Triangulation<dim> triangulation(MPI_COMM_WORLD);
    if (dim == 2)
      GridGenerator::subdivided_hyper_rectangle(triangulation, {4, 2}, Point<dim>(), Point<dim>(4, 2));
    else
      GridGenerator::subdivided_hyper_rectangle(triangulation, {4, 1, 2}, Point<dim>(), Point<dim>(4, 1, 2));
    triangulation.refine_global(dim == 2 ? 2 : 1);
    const FESystem<dim> fe(FE_Q<dim>(2), dim);
    DoFHandler<dim>     dof_handler(triangulation);
    dof_handler.distribute_dofs(fe);
    IndexSet relevant;
    DoFTools::extract_locally_relevant_dofs(dof_handler, relevant);
    LinearAlgebra::distributed::Vector<double> u(dof_handler.locally_owned_dofs(), relevant, MPI_COMM_WORLD);
    VectorTools::interpolate(dof_handler, Displacement<dim>(), u);
    u.update_ghost_values();

    // A stress that depends on the cell and the quadrature point, the same on any number of ranks;
    // Voigt xx, yy, zz, xy, yz, xz, the vertical one from the depth below z = 2.
    const auto state = [](const typename DoFHandler<dim>::active_cell_iterator &cell, const unsigned int q) {
      mpm::QuadraturePointState s;
      const Point<dim> c     = cell->center();
      const double     depth = 2 - c[dim - 1];
      const int        v     = dim - 1; // the vertical component
      s.stress[0]            = -1e4 * depth * 0.4 - 100.0 * q;
      s.stress[v]            = -1e4 * depth + 50.0 * c[0];
      s.stress[dim == 2 ? 2 : 1] = -4e3 * depth;
      s.stress[3]            = 300.0 * std::sin(c[0] + q);
      if (dim == 3)
        {
          s.stress[4] = 120.0 * std::cos(c[1] + q);
          s.stress[5] = -80.0 * c[0] * depth;
        }
      return s;
    };
    const std::map<types::material_id, mpm::HandoverMaterial> materials{{0, {0, 1800}}};
    const QGauss<dim>                                           quadrature(3);
    if (save)
      {
        mpm::save_fem_state(args[1], dof_handler, u, quadrature, state);
        return 0;
      }
    const std::string d3 = dim == 3 ? ", 0" : "";
    mpm::Parameters   parameters = mpm::parameters_from_string(
      "set Dimension = " + std::to_string(dim) + R"(
      subsection Grid
        set Lower corner = 0, 0)" + d3 + R"(
        set Upper corner = 5, )" + (dim == 3 ? "1.5, 4" : "4") + R"(
        set Cell size    = 0.25
      end
      subsection Boundary conditions
        set )" + (dim == 3 ? "z" : "y") + R"( min = no-slip
        set x min = free-slip
      end
      subsection Solver
        set Maximum number of steps = 100
        set Local damping = 0.05
        set Gravity = 0, )" + (dim == 3 ? "0, " : "") + R"(-9.81
      end
      subsection Materials
        set Names = soil
      end
      subsection Material soil
        set Model = linear elastic
        subsection linear elastic
          set Young's modulus = 2e6
          set Poisson's ratio = 0.3
        end
      end
      subsection Output
        set Output interval      = 0
        set Write particle table = true
        set Progress interval    = 0
        set Directory            = )" + args[0] + "\nend\n");
    const mpm::GeneratedBody<dim> body =
      args.size() == 2 ? mpm::points_on_lattice(dof_handler, u, quadrature, state, materials,
                                                mpm::lattice_handover<dim>(parameters, 2)) :
                         mpm::points_at_quadrature_points(dof_handler, u, quadrature, state, materials);
    mpm::Simulator<dim> simulator(parameters, MPI_COMM_WORLD);
    simulator.setup({body});
    while (!simulator.finished())
      simulator.advance();
    simulator.finish();
    return 0;
  }
} // namespace

int main(int argc, char **argv)
{
  Utilities::MPI::MPI_InitFinalize mpi(argc, argv, 1);
  try
    {
      std::vector<std::string> args(argv + 1, argv + argc);
      const bool three_d = !args.empty() && args[0] == "--3d";
      if (three_d)
        args.erase(args.begin());
      return three_d ? run<3>(args) : run<2>(args);
    }
  catch (const std::exception &e)
    {
      std::cerr << "fem_handover_run: " << e.what() << std::endl;
      return 1;
    }
}
