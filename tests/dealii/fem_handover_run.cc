// A hand-over from a distributed FEM (parallel::distributed::Triangulation, FE_Q(2)^2, a ghosted
// distributed displacement) stepped 100 steps by the MPM, writing its particle tables into the
// folder given as argument. Run on 1 and 2 ranks by ctest, whose compare_np.py asserts the
// results agree point by point (each rank hands over its own cells' points; setup gathers them).
// A second argument "lattice" hands over with placement (b), 2x2 points per MPM cell.
// "fem_handover_run --save FILE" writes the FEM state instead (fem_state_file.h), for the
// executable's Initial state/Source = FEM file.
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

using namespace dealii;

namespace
{
  constexpr int dim = 2;

  // A smooth small displacement (not linear: the FE's interpolation of it is what is handed over).
  class Displacement : public Function<dim>
  {
  public:
    Displacement()
      : Function<dim>(dim)
    {}
    double value(const Point<dim> &p, const unsigned int c) const override
    {
      return c == 0 ? 0.01 * std::sin(p[0]) * p[1] : -0.02 * p[1] * (2 - 0.1 * p[0]);
    }
  };
} // namespace

int main(int argc, char **argv)
{
  Utilities::MPI::MPI_InitFinalize mpi(argc, argv, 1);
  try
    {
      const bool save = argc == 3 && std::string(argv[1]) == "--save";
      AssertThrow(argc == 2 || (argc == 3 && (save || std::string(argv[2]) == "lattice")),
                  ExcMessage("usage: fem_handover_run OUTPUT_DIRECTORY [lattice] | --save FILE"));
      parallel::distributed::Triangulation<dim> triangulation(MPI_COMM_WORLD);
      GridGenerator::subdivided_hyper_rectangle(triangulation, {4, 2}, Point<dim>(0, 0), Point<dim>(4, 2));
      triangulation.refine_global(2);
      const FESystem<dim> fe(FE_Q<dim>(2), dim);
      DoFHandler<dim>     dof_handler(triangulation);
      dof_handler.distribute_dofs(fe);
      IndexSet relevant;
      DoFTools::extract_locally_relevant_dofs(dof_handler, relevant);
      LinearAlgebra::distributed::Vector<double> u(dof_handler.locally_owned_dofs(), relevant, MPI_COMM_WORLD);
      VectorTools::interpolate(dof_handler, Displacement(), u);
      u.update_ghost_values();

      // A stress that depends on the cell and the quadrature point, the same on any number of ranks.
      const auto state = [](const DoFHandler<dim>::active_cell_iterator &cell, const unsigned int q) {
        mpm::QuadraturePointState s;
        const Point<dim> c = cell->center();
        s.stress[0]        = -1e4 * (2 - c[1]) * 0.4 - 100.0 * q;
        s.stress[1]        = -1e4 * (2 - c[1]) + 50.0 * c[0];
        s.stress[2]        = -4e3 * (2 - c[1]);
        s.stress[3]        = 300.0 * std::sin(c[0] + q);
        return s;
      };
      const std::map<types::material_id, mpm::HandoverMaterial> materials{{0, {0, 1800}}};
      if (save)
        {
          mpm::save_fem_state(argv[2], dof_handler, u, QGauss<dim>(3), state);
          return 0;
        }
      mpm::Parameters parameters = mpm::parameters_from_string(std::string(R"(
        set Dimension = 2
        subsection Grid
          set Lower corner = 0, 0
          set Upper corner = 5, 4
          set Cell size    = 0.25
        end
        subsection Boundary conditions
          set y min = no-slip
          set x min = free-slip
        end
        subsection Solver
          set Maximum number of steps = 100
          set Local damping = 0.05
          set Gravity = 0, -9.81
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
          set Directory            = )") + argv[1] + "\nend\n");
      const mpm::GeneratedBody<dim> body =
        argc == 3 ? mpm::points_on_lattice(dof_handler, u, QGauss<dim>(3), state, materials,
                                           mpm::lattice_handover<dim>(parameters, 2)) :
                    mpm::points_at_quadrature_points(dof_handler, u, QGauss<dim>(3), state, materials);
      mpm::Simulator<dim> simulator(parameters, MPI_COMM_WORLD);
      simulator.setup({body});
      while (!simulator.finished())
        simulator.advance();
      simulator.finish();
    }
  catch (const std::exception &e)
    {
      std::cerr << "fem_handover_run: " << e.what() << std::endl;
      return 1;
    }
  return 0;
}
