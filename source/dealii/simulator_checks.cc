// A Simulator's loss check: every point and all the mass accounted for after every history row.
#include "simulator_state.h"

namespace mpm
{
  template <int dim>
  std::pair<double, double> Simulator<dim>::State::check_losses(const PointTotals<dim, double> &totals)
  {
    double       local[2] = {double(losses.n_dropped), losses.dropped_mass}, global[2] = {local[0], local[1]};
    if (parallel)
      dealii::Utilities::MPI::sum(dealii::ArrayView<const double>(local, 2), communicator,
                                  dealii::ArrayView<double>(global, 2));
    const long   removed      = totals.n_removed + static_cast<long>(global[0]);
    const double removed_mass = totals.removed_mass + global[1];
    const double balance      = (totals.mass + removed_mass - losses.initial_mass) / losses.initial_mass;
    n_removed                 = removed;
    losses.worst_mass_balance        = std::max(losses.worst_mass_balance, std::abs(balance));
    const std::string when    = " at t = " + dealii::Utilities::to_string(time) + " s (step " + std::to_string(step) + ")";
    AssertThrow(totals.n_points + removed == losses.n_points_initial,
                dealii::ExcMessage("Internal error (loss check)" + when + ": " + std::to_string(totals.n_points) +
                                   " material points in the grid and " + std::to_string(removed) +
                                   " removed make " + std::to_string(totals.n_points + removed) + ", not the " +
                                   std::to_string(losses.n_points_initial) + " the run started with."));
    const double round_off = engine->relative_mass_round_off();
    AssertThrow(std::abs(balance) <= round_off,
                dealii::ExcMessage("Internal error (loss check)" + when + ": the mass in the grid (" +
                                   dealii::Utilities::to_string(totals.mass) + " kg) and the mass removed (" +
                                   dealii::Utilities::to_string(removed_mass) + " kg) differ from the initial " +
                                   dealii::Utilities::to_string(losses.initial_mass) + " kg by a relative " +
                                   dealii::Utilities::to_string(balance) + ", beyond round-off (" +
                                   dealii::Utilities::to_string(round_off) + ")."));
    return {removed_mass, balance};
  }

  template std::pair<double, double> Simulator<2>::State::check_losses(const PointTotals<2, double> &);
  template std::pair<double, double> Simulator<3>::State::check_losses(const PointTotals<3, double> &);
} // namespace mpm
