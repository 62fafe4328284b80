#include <mpm/dealii/guards.h>
#include <mpm/dealii/run_forecast.h>

#include <deal.II/base/mpi.h>

#include <algorithm>
#include <cmath>
#include <sstream>

namespace mpm
{
  namespace
  {
    std::string number(const double x, const int digits = 4)
    {
      std::ostringstream s;
      s.precision(digits);
      s << x;
      return s.str();
    }
  } // namespace

  void print_run_forecast(std::ostream &out, const Parameters &p, MPI_Comm communicator, const bool prefailure_stage)
  {
    check_memory(p, communicator);
    const unsigned int n_ranks = dealii::Utilities::MPI::n_mpi_processes(communicator);
    if (dealii::Utilities::MPI::this_mpi_process(communicator) != 0)
      return;
    const MemoryEstimate e     = estimate_memory(p, -1, n_ranks);
    const FirstStep      first = first_time_step(p);
    const bool from_fem = p.initial_state.source != "prm bodies" || prefailure_stage;

    out << "dealii-mpm: the scene passed the checks made before a run generates its points; nothing was run or "
           "written.\n";
    out << "  grid: ";
    for (unsigned int d = 0; d < p.dim; ++d)
      out << (d ? " x " : "") << std::round((p.upper[d] - p.lower[d]) / p.cell_size);
    out << " cells of " << number(p.cell_size) << " m (" << number(e.n_cells, 10) << " cells, "
        << number(e.n_nodes, 10) << " nodes), " << p.dim << "D\n";
    if (from_fem) // the points are those of the FEM state (its quadrature points or a lattice)
      out << "  material points: those of "
          << (prefailure_stage ? "the pre-failure analysis" : "Initial state/FEM file")
          << ", not counted here (the memory below counts the bodies' instead)\n";
    else
      out << "  material points: about " << number(std::round(e.n_points), 10) << " in " << p.bodies.size()
          << (p.bodies.size() == 1 ? " body" : " bodies") << ", counted from the volumes and Points per cell "
          << "direction\n";
    if (first.set_by.empty())
      out << "  first time step: not predicted (no body or FEM material gives a wave speed)\n";
    else
      {
        out << "  first time step: " << number(first.dt) << " s";
        if (p.adaptive_time_step)
          out << " (CFL number " << number(p.cfl) << " x " << number(p.cell_size) << " m / (c_el " << number(first.c_el)
              << " + largest initial speed " << number(first.v0) << ") m/s)";
        else
          out << " (Solver/Fixed time step)";
        // The run's step follows its stiffest point (Simulator::setup), which a field drawn at the
        // points makes stiffer than the mean the forecast knows.
        const bool random_modulus =
          std::any_of(p.materials.begin(), p.materials.end(), [](const MaterialParameters<double> &m) {
            return m.field_parameter == FieldParameter::youngs_modulus;
          });
        if (p.adaptive_time_step && random_modulus)
          out << " with the mean Young's modulus; the run's step is set by its stiffest point's, and shorter";
        out << "; about " << number(std::ceil(first.steps), 10) << " steps to End time = " << number(p.end_time)
            << " s at that step"
            << (first.landing ? " (each cut to land on an output time)" :
                p.adaptive_time_step ? " (more where the points speed up)" : "")
            << (p.max_steps > 0 && first.steps >= p.max_steps ? ", Solver/Maximum number of steps" : "") << "\n";
      }
    out << "  outputs: " << number(predicted_outputs(p), 10);
    if (p.output.interval > 0)
      out << " (every " << number(p.output.interval) << " s, the initial state included)";
    else
      out << " (the initial and final states)";
    out << " into '" << p.output.directory << "'\n";
    const double GB = 1e9;
    out << "  memory: about " << number(e.total(n_ranks) / GB, 3) << " GB in all";
    if (n_ranks > 1)
      out << ", " << number(e.of_one_rank(n_ranks) / GB, 3) << " GB on each of " << n_ranks << " ranks";
    out << " (deal.II's grid and the nodes " << number(e.grid_bytes / GB, 3) << " GB, the points "
        << number(e.point_bytes / GB, 3) << " GB, on every rank the program and the bodies' generation "
        << number((e.per_rank_bytes - e.per_rank_grid_bytes) / GB, 3) << " GB";
    if (e.per_rank_grid_bytes > 0)
      out << ", the coarse grid and the block tables " << number(e.per_rank_grid_bytes / GB, 3) << " GB";
    out << "; doc/guards.md, \"The memory estimate\")\n";
    out << "  backend: " << p.backend.name << " in " << (p.backend.single_precision ? "float" : "double") << ", " << n_ranks
        << " rank(s)" << std::endl;
  }
} // namespace mpm
