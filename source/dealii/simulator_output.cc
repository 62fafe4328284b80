// A Simulator's screen header, time history and field output.
#include "simulator_state.h"

namespace mpm
{
  template <int dim>
  void Simulator<dim>::State::print_header()
  {
    const HostGrid<dim, double> lattice = lattice_geometry<dim>(parameters);
    long                        n_cells = 1, n_nodes = 1;
    for (int d = 0; d < dim; ++d)
      {
        n_cells *= lattice.n_cells[d];
        n_nodes *= lattice.n_cells[d] + 1;
      }
    pcout << "dealii-mpm: " << dim << "D, " << n_cells << " cells, " << n_nodes << " nodes, " << losses.n_points_initial
          << " material points, " << n_ranks << " MPI rank(s), backend " << parameters.backend.name
          << (parameters.backend.single_precision ? " in float" : "") << "\n"
          << "  elastic wave speed " << c_el << " m/s, end time " << parameters.end_time << " s, output in '"
          << output->directory() << "'" << std::endl;
    if (parameters.cells_per_grid_cell > 1)
      pcout << "  deal.II's grid: " << n_cells / dealii::Utilities::pow(parameters.cells_per_grid_cell, dim)
            << " cells of " << parameters.cells_per_grid_cell << "^" << dim << " (Grid/Cells per deal.II cell)"
            << std::endl;
    if (engine->follows_material() && parallel)
      pcout << "  nodes near the material: " << engine->n_active_nodes() << " of the " << n_nodes
            << " (blocks of " << parameters.active_block_cells << " cells; summed over the ranks, a node on each "
            << "rank that holds it), chosen again at every re-sort; deal.II's grid fine only near the "
               "material"
            << std::endl;
    else if (engine->follows_material())
      pcout << "  nodes near the material: " << engine->n_active_nodes() << " of the " << n_nodes
            << " (blocks of " << parameters.active_block_cells << " cells), chosen again once a point is more than "
            << migration.resort_at << " cells out of the cell it was in" << std::endl;
    else if (parallel && parameters.active_block_cells > 0)
      pcout << "  Grid/Nodes = near material with Backend = cuda is for one rank so far: each rank keeps every "
               "node of its part of the grid"
            << std::endl;
  }

  template <int dim>
  void Simulator<dim>::State::record_history()
  {
    settle();
    timed("history", [&]() {
      const auto local  = engine->totals();
      const auto totals = parallel ? global_totals<dim>(local, communicator) : local;
      const auto [removed_mass, balance] = check_losses(totals);
      typename OutputWriter<dim>::HistoryRow row{time, dt, work_of_gravity, step, n_removed, totals};
      row.removed_mass = removed_mass;
      row.mass_balance = balance;
      row.min_points_per_rank = static_cast<long>(global_min(double(local.n_points)));
      row.max_points_per_rank = static_cast<long>(global_max(double(local.n_points)));
      row.n_resorts           = migration.n_resorts;
      row.n_repartitions      = migration.n_repartitions;
      row.n_sent              = parallel ? static_cast<long>(sum(double(points->n_sent), communicator)) : 0;
      output->write_history(row);
    });
  }

  template <int dim>
  void Simulator<dim>::State::write_output()
  {
    settle();
    if (time == 0 && grid_build.valid())
      {
        engine->snapshot(output->next_snapshot());
        initial_output_pending = true;
        return;
      }
    join_grid();
    dealii::TimerOutput::Scope scope(timer, "output");
    PointSnapshot<dim> &snapshot = output->next_snapshot();
    // The nodes first: their download waits for the device, the points' does not (the
    // CUDA engine's come down while the next steps are queued; the particle task waits).
    if (!grid) // one rank, nodes near the material: the grid files show the engine's cells
      {
        typename GridSnapshot<dim>::LatticeCells cells;
        engine->cells_with_mass(cells);
        engine->start_snapshot(snapshot);
        return output->write_fields(time, std::move(cells));
      }
    engine->nodal_to(*grid);
    engine->start_snapshot(snapshot);
    output->write_fields(time, *grid);
  }

  template void Simulator<2>::State::print_header();
  template void Simulator<3>::State::print_header();
  template void Simulator<2>::State::record_history();
  template void Simulator<3>::State::record_history();
  template void Simulator<2>::State::write_output();
  template void Simulator<3>::State::write_output();
} // namespace mpm
