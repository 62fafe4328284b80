// A Simulator's points as the library hands them out and takes them back.
#include "simulator_state.h"

namespace mpm
{
  template <int dim>
  HostPoints<dim, double> Simulator<dim>::points() const
  {
    AssertThrow(state->set_up, dealii::ExcMessage("Simulator::points() needs setup() first."));
    state->settle(); // a step queued on the GPU has ended, and passed the checks after it
    PointSnapshot<dim> snapshot;
    state->engine->snapshot(snapshot);
    return std::move(snapshot.points);
  }

  template <int dim>
  void Simulator<dim>::set_points(const HostPoints<dim, double> &new_points)
  {
    State &s = *state;
    AssertThrow(s.set_up, dealii::ExcMessage("Simulator::set_points() needs setup() first."));
    s.settle();
    PointSnapshot<dim> snapshot;
    s.engine->snapshot(snapshot);
    // What is wrong with this rank's points, if anything; every rank stops when one does
    // (the migration below is collective).
    std::string       wrong;
    const Parameters &p = s.parameters;
    if (new_points.size() != snapshot.points.size())
      wrong = std::to_string(new_points.size()) + " points given, the run holds " +
              std::to_string(snapshot.points.size()) +
              (s.parallel ? " on MPI rank " + std::to_string(dealii::Utilities::MPI::this_mpi_process(s.communicator)) :
                            std::string()) +
              "; give the same points, in the order points() returned them.";
    // A point placed outside the grid would be lost without a word (the handler drops it).
    for (int i = 0; i < new_points.size() && wrong.empty(); ++i)
      for (int d = 0; d < dim && wrong.empty(); ++d)
        if (new_points.material[i] >= 0 &&
            !(new_points.position[d][i] >= p.lower[d] && new_points.position[d][i] <= p.upper[d]))
          wrong = "point " + std::to_string(i) + " at " + std::string("xyz").substr(d, 1) + " = " +
                  dealii::Utilities::to_string(new_points.position[d][i]) +
                  " lies outside the grid (Grid/Lower corner and Upper corner: [" +
                  dealii::Utilities::to_string(p.lower[d]) + ", " + dealii::Utilities::to_string(p.upper[d]) + "]).";
    const bool refused_anywhere = s.global_max(wrong.empty() ? 0 : 1) > 0;
    AssertThrow(wrong.empty(), dealii::ExcMessage("Simulator::set_points(): " + wrong));
    AssertThrow(!refused_anywhere, dealii::ExcMessage("Simulator::set_points(): another MPI rank's points were "
                                                      "refused (its message says why)."));
    // The loss checks take the points as given: their masses may have changed (the new
    // initial mass), and on several ranks those marked as having left the grid are dropped.
    const auto rebase_initial_mass = [&]() {
      const PointTotals<dim, double> t = s.engine->totals();
      s.losses.initial_mass = s.global_sum(t.mass + t.removed_mass + s.losses.dropped_mass);
    };
    if (!s.parallel)
      {
        s.engine->load(new_points, snapshot.labels);
        return rebase_initial_mass();
      }
    for (int i = 0; i < new_points.size(); ++i)
      if (new_points.material[i] < 0)
        {
          ++s.losses.n_dropped;
          s.losses.dropped_mass += new_points.mass[i];
        }
    // Points may have been moved any distance: every rank gets all of them (as setup()
    // gets handed-over points) and keeps those in its cells, ids and labels kept.
    dealii::TimerOutput::Scope scope(s.timer, "migrate points");
    std::vector<double>        packed{double(new_points.size())};
    AssertThrow(new_points.n_state_variables() == snapshot.points.n_state_variables(),
                dealii::ExcMessage("Simulator::set_points(): " + state_variable_count_mismatch(
                                                                  new_points.n_state_variables(),
                                                                  snapshot.labels->state_variable_names)));
    for_each_point_array<dim>(new_points, new_points, [&](const auto &array, const auto &) {
      packed.insert(packed.end(), array.begin(), array.end());
    });
    packed.insert(packed.end(), snapshot.labels->id.begin(), snapshot.labels->id.end());
    for (int d = 0; d < dim; ++d)
      packed.insert(packed.end(), snapshot.labels->initial_position[d].begin(),
                    snapshot.labels->initial_position[d].end());
    const std::vector<std::vector<double>> ranks = dealii::Utilities::MPI::all_gather(s.communicator, packed);
    int                                    total = 0;
    for (const std::vector<double> &from_rank : ranks)
      total += static_cast<int>(from_rank[0]);
    PointSnapshot<dim> all;
    auto               labels = std::make_shared<PointLabels<dim>>();
    labels->state_variable_names = snapshot.labels->state_variable_names;
    all.points.fields = new_points.fields;
    all.points.set_n_state_variables(new_points.n_state_variables());
    all.points.resize(total);
    int offset = 0;
    for (const std::vector<double> &from_rank : ranks)
      {
        const int   n  = static_cast<int>(from_rank[0]);
        std::size_t at = 1;
        for_each_point_array<dim>(all.points, all.points, [&](auto &array, auto &) {
          using T = typename std::decay_t<decltype(array)>::value_type;
          for (int k = 0; k < n; ++k)
            array[offset + k] = static_cast<T>(from_rank[at++]);
        });
        for (int k = 0; k < n; ++k)
          labels->id.push_back(static_cast<dealii::types::particle_index>(from_rank[at++]));
        for (int d = 0; d < dim; ++d)
          for (int k = 0; k < n; ++k)
            labels->initial_position[d].push_back(from_rank[at++]);
        offset += n;
      }
    all.labels = labels;
    s.points->replace(all);
    s.refine_near_material();
    s.engine->load(*s.points);
    ++s.migration.n_resorts;
    if (s.balance())
      s.engine->load(*s.points);
    rebase_initial_mass();
  }

  template HostPoints<2, double> Simulator<2>::points() const;
  template void Simulator<2>::set_points(const HostPoints<2, double> &);
  template HostPoints<3, double> Simulator<3>::points() const;
  template void Simulator<3>::set_points(const HostPoints<3, double> &);
} // namespace mpm
