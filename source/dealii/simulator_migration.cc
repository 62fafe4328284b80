// A Simulator's points among the cells and ranks: re-sorts, repartitions by work, deal.II's grid refined
// near the material, and when the points must be sorted again.
#include "simulator_state.h"

namespace mpm
{
  template <int dim>
  double Simulator<dim>::State::imbalance() const
  {
    return engine ? points->imbalance(static_cast<double>(engine->n_points())) : points->imbalance();
  }

  template <int dim>
  bool Simulator<dim>::State::balance()
  {
    if (!parallel || !(parameters.parallel.load_balance_threshold > 0))
      return false;
    const double before = imbalance();
    if (before <= parameters.parallel.load_balance_threshold ||
        before <= migration.balanced + 0.5 * (parameters.parallel.load_balance_threshold - 1))
      return false;
    dealii::TimerOutput::Scope scope(timer, "repartition");
    output->finish(); // a grid output in flight reads the DoFHandler
    if (engine)
      engine->sync(*points); // the handler's points move with their cells
    points->repartition();
    ++migration.n_repartitions;
    migration.balanced = points->imbalance();
    pcout << "  repartitioned the grid by work: max/mean work per rank " << before << " -> " << migration.balanced
          << std::endl;
    return true;
  }

  template <int dim>
  bool Simulator<dim>::State::refine_near_material()
  {
    if (!parallel || !grid->coarse_away_from_material())
      return false;
    return points->refine_near_points([&]() {
      if (output)
        output->finish(); // a grid output in flight reads the DoFHandler
    });
  }

  template <int dim>
  void Simulator<dim>::State::partition_by_current_work()
  {
    if (!parallel || !(parameters.parallel.load_balance_threshold > 0))
      return;
    output->finish(); // a grid output in flight reads the DoFHandler
    points->repartition();
    ++migration.n_repartitions;
    migration.balanced = points->imbalance();
  }

  template <int dim>
  void Simulator<dim>::State::resort()
  {
    const PointTotals<dim, double> held    = engine->totals();
    const unsigned int             dropped = engine->resort(*points);
    AssertThrow(static_cast<long>(dropped) == held.n_removed,
                dealii::ExcMessage("Internal error (loss check): a re-sort dropped " + std::to_string(dropped) +
                                   " points, but " + std::to_string(held.n_removed) +
                                   " had left the grid on this rank."));
    losses.n_dropped += held.n_removed;
    losses.dropped_mass += held.removed_mass;
    ++migration.n_resorts;
    migration.drift_bound = 0; // every point is in its home cell now
  }

  template <int dim>
  void Simulator<dim>::State::set_resort_distance()
  {
    // One rank, nodes near the material: every cell within Active block size cells of a
    // point's home cell is kept. The pressure averaging sums over the cells the points
    // have moved to within the step (less than a cell, CFL <= 1): choosing the nodes again
    // once a point is B - 1 cells out keeps those cells' sums.
    if (!parallel)
      migration.resort_at = !engine->follows_material() ? 1e300 :
                  parameters.pressure_averaging ?
                                                std::min(engine->active_node_margin(), parameters.active_block_cells - 1.0) :
                                                engine->active_node_margin();
    else
      {
        migration.resort_at   = std::min(parameters.parallel.resort_distance * safe_distance_outside_home_cell(parameters.shape_function),
                                         parameters.pressure_averaging ? 0.5 : 1e300);
        migration.ghost_width = parameters.cells_per_grid_cell;
      }
  }

  template <int dim>
  double Simulator<dim>::State::step_displacement_bound(const double dt) const
  {
    if (parameters.scheme != UpdateScheme::musl || settings.affine_state_variable >= 0)
      return std::numeric_limits<double>::infinity();
    return dt * std::max(max_speed, max_removed_speed) / h * (1 + 1e-9); // 1e-9: the sums' round-off
  }

  template double Simulator<2>::State::imbalance() const;
  template double Simulator<3>::State::imbalance() const;
  template bool Simulator<2>::State::balance();
  template bool Simulator<3>::State::balance();
  template bool Simulator<2>::State::refine_near_material();
  template bool Simulator<3>::State::refine_near_material();
  template void Simulator<2>::State::partition_by_current_work();
  template void Simulator<3>::State::partition_by_current_work();
  template void Simulator<2>::State::resort();
  template void Simulator<3>::State::resort();
  template void Simulator<2>::State::set_resort_distance();
  template void Simulator<3>::State::set_resort_distance();
  template double Simulator<2>::State::step_displacement_bound(double) const;
  template double Simulator<3>::State::step_displacement_bound(double) const;
} // namespace mpm
