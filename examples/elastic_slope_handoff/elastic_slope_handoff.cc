// elastic_slope_handoff: a user's own deal.II program solves the gravity loading of a slope with
// the finite element method, then hands its state over to dealii-mpm and lets the MPM carry on.
//
// The story. Before asking how far a slope runs out, an engineer computes its state under its own
// weight: the displacement and the stresses of the gravity loading. That is a static problem, which
// an FEM solves in a moment, where an explicit MPM would spend seconds of simulated time (ep2-3De
// spends 8 s of its slump run on it). Here the FEM state is handed over to the MPM, in both of the
// library's placements (doc/library.md): (a) one material point per quadrature point, (b) points
// on the MPM's own lattice with the stresses projected onto them; the MPM steps on. Since the
// FEM state is in equilibrium, the MPM must find the slope at rest: no damping, gravity at once,
// twenty elastic wave transits, and the largest point speed and stress change measured in the units
// of the problem, sqrt(g H) and rho g H. Plane strain by default; `elastic_slope_handoff 3` runs the
// slope extruded in 3D, `elastic_slope_handoff 2 b` placement (b) alone; on any number of MPI
// ranks (`mpirun -np 2 elastic_slope_handoff`).
//
// The parts, top to bottom:
//   1. the slope: a mesh of a box, its top bent into the slope's profile; material_id 0; the mesh
//      distributed over the ranks (parallel::distributed::Triangulation);
//   2. the FEM: linear elasticity (plane strain) under gravity with FE_Q(2)^2, rollers on the sides,
//      a fixed base; its own assembly, CG with Trilinos' algebraic multigrid;
//   3. the quadrature-point history: the stress of each Gauss point, in deal.II's CellDataStorage;
//   4. the MPM scene from prm text: the same material, a grid around the slope, the same boundaries,
//      and the equilibration of the state handed over in the MPM's discretisation;
//   5. the hand-over and the MPM run, stepped by this program;
//   6. the check: how far the MPM moves the handed-over state.
#include <mpm/dealii/fem_handover.h>
#include <mpm/dealii/fem_handover_lattice.h>
#include <mpm/dealii/parameters.h>
#include <mpm/dealii/simulator.h>

#include <deal.II/base/conditional_ostream.h>
#include <deal.II/base/function.h>
#include <deal.II/base/mpi.h>
#include <deal.II/base/quadrature_lib.h>
#include <deal.II/base/quadrature_point_data.h>
#include <deal.II/distributed/tria.h>
#include <deal.II/dofs/dof_handler.h>
#include <deal.II/dofs/dof_tools.h>
#include <deal.II/fe/fe_q.h>
#include <deal.II/fe/fe_system.h>
#include <deal.II/fe/fe_values.h>
#include <deal.II/grid/grid_generator.h>
#include <deal.II/grid/grid_tools.h>
#include <deal.II/lac/affine_constraints.h>
#include <deal.II/lac/dynamic_sparsity_pattern.h>
#include <deal.II/lac/solver_cg.h>
#include <deal.II/lac/sparsity_tools.h>
#include <deal.II/lac/trilinos_precondition.h>
#include <deal.II/lac/trilinos_sparse_matrix.h>
#include <deal.II/lac/trilinos_vector.h>
#include <deal.II/numerics/vector_tools.h>

#include <algorithm>
#include <cmath>
#include <iostream>
#include <string>
#include <vector>

using namespace dealii;

namespace
{
  // Slope: 30 m long, 10 m high behind the crest (x < 10 m), falling at 1:2 (26.6 deg) to 5 m at
  // x = 20 m, then level; dry soil, rho = 2000 kg/m^3, E = 20 MPa, nu = 0.3, g = 9.81 m/s^2.
  constexpr double length = 30, H = 10, rho = 2000, E = 20e6, nu = 0.3, g = 9.81;

  double surface(const double x)
  {
    return x < 10 ? H : (x < 20 ? H - 0.5 * (x - 10) : H / 2);
  }

  // The quadrature-point history of the FEM: it derives from mpm::QuadraturePointState (stress in
  // Voigt order, plastic strain), which is what the hand-over takes.
  struct PointHistory : mpm::QuadraturePointState
  {};
} // namespace

// The whole program for a dimension, 2 (plane strain, the default) or 3 (the same slope extruded
// 2 m in y between rollers: `elastic_slope_handoff 3`), and a placement, 'a' or 'b'.
template <int dim>
int run(const char placement)
{
  {
    {
      // 1. The slope: 60 x 20 cells of a box (x 30 m, height H; in 3D 4 cells across 2 m in y),
      // each point's height scaled to the slope's profile. Height is the last coordinate. The
      // mesh is distributed over the MPI ranks (p4est); each rank assembles its own cells.
      const MPI_Comm     comm = MPI_COMM_WORLD;
      ConditionalOStream pcout(std::cout, Utilities::MPI::this_mpi_process(comm) == 0);
      parallel::distributed::Triangulation<dim> triangulation(comm);
      std::vector<unsigned int> cells{60};
      Point<dim>                upper;
      upper[0] = length;
      if (dim == 3)
        cells.push_back(4), upper[1] = 2;
      cells.push_back(20);
      upper[dim - 1] = H;
      // colorize: boundary ids 0, 1 at x = 0, 30; 2, 3 at the next axis' ends; 4, 5 in 3D.
      GridGenerator::subdivided_hyper_rectangle(triangulation, cells, Point<dim>(), upper, /*colorize=*/true);
      GridTools::transform(
        [](const Point<dim> &p) {
          Point<dim> q = p;
          q[dim - 1]   = p[dim - 1] * surface(p[0]) / H;
          return q;
        },
        triangulation);
      for (const auto &cell : triangulation.active_cell_iterators())
        cell->set_material_id(0); // colorize numbered the cells too: one soil here

      // 2. Linear elasticity under gravity (plane strain), Q2 displacements.
      const FESystem<dim> fe(FE_Q<dim>(2), dim);
      DoFHandler<dim>     dof_handler(triangulation);
      dof_handler.distribute_dofs(fe);
      const FEValuesExtractors::Vector displacement(0);

      // A fixed base; rollers on the sides (the normal component fixed).
      IndexSet relevant;
      DoFTools::extract_locally_relevant_dofs(dof_handler, relevant);
      AffineConstraints<double> constraints(relevant);
      const types::boundary_id base = 2 * (dim - 1);
      VectorTools::interpolate_boundary_values(dof_handler, base, Functions::ZeroFunction<dim>(dim), constraints);
      for (int axis = 0; axis < dim - 1; ++axis)
        for (const types::boundary_id side : {2 * axis, 2 * axis + 1})
          VectorTools::interpolate_boundary_values(dof_handler, side, Functions::ZeroFunction<dim>(dim), constraints,
                                                   fe.component_mask(FEValuesExtractors::Scalar(axis)));
      constraints.close();

      const IndexSet         owned = dof_handler.locally_owned_dofs();
      DynamicSparsityPattern dsp(relevant);
      DoFTools::make_sparsity_pattern(dof_handler, dsp, constraints, false);
      SparsityTools::distribute_sparsity_pattern(dsp, owned, comm, relevant);
      TrilinosWrappers::SparseMatrix matrix;
      matrix.reinit(owned, owned, dsp, comm);
      TrilinosWrappers::MPI::Vector rhs(owned, comm), solution(owned, comm);

      const double    lambda = E * nu / ((1 + nu) * (1 - 2 * nu)), mu = E / (2 * (1 + nu));
      const QGauss<dim> quadrature(3);
      FEValues<dim>     fe_values(fe, quadrature, update_values | update_gradients | update_JxW_values);
      const unsigned int n_dofs = fe.n_dofs_per_cell(), n_q = quadrature.size();
      FullMatrix<double> cell_matrix(n_dofs, n_dofs);
      Vector<double>     cell_rhs(n_dofs);
      std::vector<types::global_dof_index> dofs(n_dofs);
      Tensor<1, dim>                       gravity;
      gravity[dim - 1] = -g;
      for (const auto &cell : dof_handler.active_cell_iterators())
        {
          if (!cell->is_locally_owned())
            continue;
          fe_values.reinit(cell);
          cell_matrix = 0;
          cell_rhs    = 0;
          for (unsigned int q = 0; q < n_q; ++q)
            for (unsigned int i = 0; i < n_dofs; ++i)
              {
                const SymmetricTensor<2, dim> eps_i = fe_values[displacement].symmetric_gradient(i, q);
                for (unsigned int j = 0; j < n_dofs; ++j)
                  {
                    const SymmetricTensor<2, dim> eps_j = fe_values[displacement].symmetric_gradient(j, q);
                    cell_matrix(i, j) += (lambda * trace(eps_i) * trace(eps_j) + 2 * mu * (eps_i * eps_j)) *
                                         fe_values.JxW(q);
                  }
                cell_rhs(i) += rho * (gravity * fe_values[displacement].value(i, q)) * fe_values.JxW(q);
              }
          cell->get_dof_indices(dofs);
          constraints.distribute_local_to_global(cell_matrix, cell_rhs, dofs, matrix, rhs);
        }
      matrix.compress(VectorOperation::add);
      rhs.compress(VectorOperation::add);

      TrilinosWrappers::PreconditionAMG                 amg;
      TrilinosWrappers::PreconditionAMG::AdditionalData amg_data;
      amg_data.elliptic              = true;
      amg_data.higher_order_elements = true;
      DoFTools::extract_constant_modes(dof_handler, ComponentMask(dim, true), amg_data.constant_modes);
      amg.initialize(matrix, amg_data);
      SolverControl                           control(1000, 1e-12 * rhs.l2_norm());
      SolverCG<TrilinosWrappers::MPI::Vector> cg(control);
      cg.solve(matrix, solution, rhs, amg);
      constraints.distribute(solution);
      TrilinosWrappers::MPI::Vector displacement_field(owned, relevant, comm); // with the ghost values
      displacement_field = solution;
      pcout << "FEM: " << triangulation.n_active_cells() << " cells, " << dof_handler.n_dofs()
                << " DoFs, CG + AMG converged in " << control.last_step() << " iterations" << std::endl;

      // 3. The stress of each quadrature point, sigma = lambda tr(eps) I + 2 mu eps, with the
      // plane-strain sigma_zz = lambda tr(eps), kept in deal.II's quadrature-point storage
      // (this rank's cells).
      CellDataStorage<typename Triangulation<dim>::cell_iterator, PointHistory> history;
      std::vector<SymmetricTensor<2, dim>> strain(n_q);
      for (const auto &cell : dof_handler.active_cell_iterators())
        {
          if (!cell->is_locally_owned())
            continue;
          history.initialize(cell, n_q);
          fe_values.reinit(cell);
          fe_values[displacement].get_function_symmetric_gradients(displacement_field, strain);
          const auto points = history.get_data(cell);
          const int voigt[3][3] = {{0, 3, 5}, {3, 1, 4}, {5, 4, 2}}; // xx, yy, zz, xy, yz, xz
          for (unsigned int q = 0; q < n_q; ++q)
            {
              const double tr = trace(strain[q]);
              for (int c = 0; c < mpm::n_voigt; ++c)
                points[q]->stress[c] = 0;
              points[q]->stress[2] = lambda * tr; // zz: in 2D plane strain's, in 3D overwritten below
              for (int d = 0; d < dim; ++d)
                for (int e = d; e < dim; ++e)
                  points[q]->stress[voigt[d][e]] = (d == e ? lambda * tr : 0.0) + 2 * mu * strain[q][d][e];
            }
        }

      // 4. The MPM scene: the same soil, a grid of 0.5 m cells around the slope with 5 m of room
      // above it, the FEM's boundaries (rollers on the sides, a fixed base), no damping, gravity at
      // once. Its bodies section is not used: the points come from the FEM.
      //
      // Equilibrate: the FEM's stresses balance gravity in the FEM's discretisation, not exactly
      // in the MPM's (other shape functions, the points as quadrature). Before t = 0 the MPM takes
      // damped steps with the points held in place until its grid is at rest: the stresses then
      // change by that difference (reported below), and the undamped run starts in equilibrium.
      // Without it, the slope rings about the MPM's equilibrium for ever (doc/library.md).
      const std::string grid_and_boundaries =
        dim == 2 ? "set Dimension = 2\n"
                   "subsection Grid\n set Lower corner = 0, 0\n set Upper corner = 30, 15\n set Cell size = 0.5\nend\n"
                   "subsection Boundary conditions\n set x min = free-slip\n set x max = free-slip\n"
                   " set y min = no-slip\n set y max = free\nend\n"
                   "subsection Solver\n set Gravity = 0, -9.81\nend\n" :
                   "set Dimension = 3\n"
                   "subsection Grid\n set Lower corner = 0, 0, 0\n set Upper corner = 30, 2, 15\n"
                   " set Cell size = 0.5\nend\n"
                   "subsection Boundary conditions\n set x min = free-slip\n set x max = free-slip\n"
                   " set y min = free-slip\n set y max = free-slip\n set z min = no-slip\n set z max = free\nend\n"
                   "subsection Solver\n set Gravity = 0, 0, -9.81\nend\n";
      mpm::Parameters parameters = mpm::parameters_from_string(grid_and_boundaries + R"(
        subsection Solver
          set Shape function     = GIMP
          set GIMP domain update = det F
          set Local damping      = 0
        end
        subsection Initial state
          set Equilibrate = true
        end
        subsection Materials
          set Names = soil
        end
        subsection Material soil
          set Model = linear elastic
          subsection linear elastic
            set Young's modulus = 20e6
            set Poisson's ratio = 0.3
          end
        end
        subsection Output
          set Directory       = output-elastic-slope-handoff
          set Output interval = 0
        end
      )");
      const double M = E * (1 - nu) / ((1 + nu) * (1 - 2 * nu)); // P-wave modulus
      parameters.end_time = 20 * H / std::sqrt(M / rho);           // twenty elastic wave transits

      // 5. The hand-over, in the placement asked for, material_id 0 -> MPM material 0 ("soil"):
      //    (a) one point per Gauss point, its volume the Gauss weight (the FEM's own quadrature);
      //    (b) 2x2(x2) points per MPM cell on the MPM's lattice, the stresses projected onto
      //        discontinuous Q2 polynomials cell by cell and evaluated there.
      // Each rank hands over the points of its own cells; the simulator distributes them anew.
      const std::map<types::material_id, mpm::HandoverMaterial> materials{{0, {0, rho}}};
      const mpm::GeneratedBody<dim> body =
        placement == 'a' ?
          mpm::points_at_quadrature_points(dof_handler, displacement_field, quadrature, history, materials) :
          mpm::points_on_lattice(dof_handler, displacement_field, quadrature, history, materials,
                                 mpm::lattice_handover<dim>(parameters, 2));
      mpm::Simulator<dim> simulator(parameters, comm);
      simulator.setup({body});
      const mpm::HostPoints<dim, double> start = simulator.points(); // this rank's, equilibrated
      double fastest = 0;
      while (!simulator.finished())
        {
          simulator.advance();
          const mpm::HostPoints<dim, double> now = simulator.points();
          for (int i = 0; i < now.size(); ++i)
            {
              double speed = 0;
              for (int d = 0; d < dim; ++d)
                speed += now.velocity[d][i] * now.velocity[d][i];
              fastest = std::max(fastest, std::sqrt(speed));
            }
        }
      simulator.finish();

      // 6. At rest? The largest point speed against sqrt(g H), the largest stress change against
      // rho g H, and the stress change's root mean square over the points, over all ranks. (A
      // body at rest keeps its points on their ranks and in their order.)
      const mpm::HostPoints<dim, double> end = simulator.points();
      AssertThrow(end.size() == start.size(), ExcMessage("the points changed rank: the slope did not stay at rest"));
      double change = 0, sum_squares = 0;
      for (int i = 0; i < end.size(); ++i)
        {
          double point_change = 0;
          for (int c = 0; c < mpm::n_voigt; ++c)
            point_change = std::max(point_change, std::abs(end.stress[c][i] - start.stress[c][i]));
          change = std::max(change, point_change);
          sum_squares += point_change * point_change;
        }
      const double n_points     = Utilities::MPI::sum(double(end.size()), comm);
      const double speed_ratio  = Utilities::MPI::max(fastest, comm) / std::sqrt(g * H),
                   stress_ratio = Utilities::MPI::max(change, comm) / (rho * g * H),
                   stress_rms   = std::sqrt(Utilities::MPI::sum(sum_squares, comm) / n_points) / (rho * g * H);
      const mpm::EquilibrationReport &e = simulator.equilibration();
      pcout << "MPM, placement (" << placement << "): " << n_points << " points handed over on "
            << Utilities::MPI::n_mpi_processes(comm) << " MPI rank(s)\n"
            << "  equilibration before t = 0, " << e.steps << " damped steps: the stresses changed by up to "
            << e.max_stress_change / (rho * g * H) << " rho g H (r.m.s. " << e.rms_stress_change / (rho * g * H)
            << ")\n"
            << "  then " << simulator.step() << " steps to t = " << simulator.time()
            << " s (20 wave transits), no damping:\n"
            << "  largest point speed / sqrt(g H)       = " << speed_ratio << "\n"
            << "  largest stress change / (rho g H)     = " << stress_ratio << "\n"
            << "  r.m.s. stress change / (rho g H)      = " << stress_rms << std::endl;
      // The targets of the hand-over: 1e-3 for (a), 1e-2 for (b), speed and stress change.
      const double bound   = placement == 'a' ? 1e-3 : 1e-2;
      const bool   at_rest = speed_ratio < bound && stress_ratio < bound;
      pcout << (at_rest ? "the slope handed over stays at rest (below " : "FAILED: the slope handed over moves (bound ")
            << bound << ")" << std::endl;
      return at_rest ? 0 : 1;
    }
  }
}

int main(int argc, char **argv)
{
  Utilities::MPI::MPI_InitFinalize mpi(argc, argv, 1);
  try
    {
      // elastic_slope_handoff [2|3] [a|b|both]: the dimension and the placement (both by default).
      const std::string dimension = argc > 1 ? argv[1] : "2", placements = argc > 2 ? argv[2] : "both";
      AssertThrow((dimension == "2" || dimension == "3") &&
                    (placements == "a" || placements == "b" || placements == "both"),
                  ExcMessage("usage: elastic_slope_handoff [2|3] [a|b|both]"));
      int failed = 0;
      for (const char placement : {'a', 'b'})
        if (placements == "both" || placements[0] == placement)
          failed += dimension == "3" ? run<3>(placement) : run<2>(placement);
      return failed == 0 ? 0 : 1;
    }
  catch (const std::exception &e)
    {
      std::cerr << "elastic_slope_handoff: " << e.what() << std::endl;
      return 1;
    }
}
