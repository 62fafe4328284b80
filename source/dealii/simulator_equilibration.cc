// A Simulator's equilibration (Initial state/Equilibrate): damped steps at t = 0 until the points rest.
#include "simulator_state.h"

namespace mpm
{
  template <int dim>
  void Simulator<dim>::State::equilibrate()
  {
    const auto started = std::chrono::steady_clock::now();
    switch_plasticity_on_when_due(); // the materials as the first step will have them
    for (int d = 0; d < dim; ++d)
      settings.gravity[d] = parameters.gravity[d];

    PointSnapshot<dim> before;
    engine->snapshot(before);
    const HostPoints<dim, double> &p0 = before.points;
    // The reference speed sqrt(|g| H), H the extent of the points' domains along gravity.
    double g = 0;
    for (int d = 0; d < dim; ++d)
      g += parameters.gravity[d] * parameters.gravity[d];
    g = std::sqrt(g);
    double lowest = 1e300, highest = -1e300, smallest_domain = h;
    for (int i = 0; i < p0.size(); ++i)
      if (p0.material[i] >= 0)
        for (int d = 0; d < dim; ++d)
          smallest_domain = std::min(smallest_domain, p0.domain_half_length[d][i]);
    for (int i = 0; i < p0.size(); ++i)
      if (p0.material[i] >= 0 && g > 0)
        {
          double along = 0, reach = 0;
          for (int d = 0; d < dim; ++d)
            {
              along += p0.position[d][i] * parameters.gravity[d] / g;
              reach += p0.domain_half_length[d][i] * std::abs(parameters.gravity[d]) / g;
            }
          lowest  = std::min(lowest, along - reach);
          highest = std::max(highest, along + reach);
        }
    const double extent = g > 0 ? global_max(highest) + global_max(-lowest) : 0;
    equilibration.reference_speed = g > 0 ? std::sqrt(g * extent) : c_el;
    const double transit = (g > 0 ? extent : h) / c_el;

    // Damped, PIC (FLIP would keep velocities the grid does not see, undamped for ever), and
    // the points held in place: the equilibrium of the geometry given, not of one the points
    // creep into (at a free surface a point whose domain just reaches a node's support feels
    // that light node's large acceleration, and drifts).
    //
    // With GIMP the grid keeps its velocities between the steps (a dynamic relaxation on
    // the grid); rebuilt from the points, the light nodes at a free surface relax over
    // thousands of steps and leave forces that FLIP then turns into creeping point
    // velocities (doc/log.md). A light node whose points reach it with the tail of a
    // domain of half-length l has a stiffness over mass of up to c^2 sum_d 1/(l_d h),
    // so the step is cut to a Courant number of sqrt(l_min / (dim h)) (at most the
    // run's): omega dt <= 1 for the stiffest such node. Linear shape functions give no
    // such bound (a point close to a node line makes the node's ratio unbounded): there
    // the velocities are rebuilt from the points, which is stable, and slower.
    const bool   on_grid = parameters.shape_function == ShapeFunction::gimp;
    const double courant = on_grid ? std::sqrt(global_min(smallest_domain) / (dim * h)) : 1e300;
    const double damping = settings.damping, flip_fraction = settings.flip_fraction;
    settings.damping       = parameters.initial_state.equilibration_damping;
    settings.flip_fraction = 0;
    settings.hold_points   = true;
    equilibrating          = true;
    double calm            = 0; // how long the points have been at rest
    while (calm < transit)
      {
        AssertThrow(equilibration.steps < long(parameters.initial_state.equilibration_maximum_steps),
                    dealii::ExcMessage(
                      "Parameter 'Initial state/Equilibration maximum steps': after " +
                      std::to_string(equilibration.steps) + " damped steps the largest point speed is still " +
                      dealii::Utilities::to_string(max_speed / equilibration.reference_speed) +
                      " sqrt(|g| H), above 'Initial state/Equilibration tolerance' (" +
                      dealii::Utilities::to_string(parameters.initial_state.equilibration_tolerance) +
                      "). Either the state is not stable under these materials (it fails under its own "
                      "weight), or it needs more steps: raise the maximum or the tolerance."));
        const double dt = parameters.adaptive_time_step ?
                            std::min(parameters.cfl, courant) * h / (c_el + max_speed) :
                            std::min(parameters.fixed_time_step, courant * h / c_el);
        settings.hold_from_point_momentum = !on_grid || equilibration.steps == 0;
        engine_step(dt);
        ++equilibration.steps;
        calm = max_speed < parameters.initial_state.equilibration_tolerance * equilibration.reference_speed ? calm + dt : 0;
      }
    equilibrating             = false;
    settings.damping          = damping;
    settings.flip_fraction    = flip_fraction;
    settings.hold_points      = false;
    equilibration.final_speed = max_speed;

    // How far it moved the stresses, point by point (by id: the engine may reorder them).
    PointSnapshot<dim> after;
    engine->snapshot(after);
    std::unordered_map<dealii::types::particle_index, int> index;
    for (int i = 0; i < p0.size(); ++i)
      if (p0.material[i] >= 0)
        index[before.labels->id[i]] = i;
    const HostPoints<dim, double> &p1 = after.points;
    double largest = 0, squares = 0, compared = 0;
    for (int i = 0; i < p1.size(); ++i)
      {
        const auto found = index.find(after.labels->id[i]);
        if (p1.material[i] < 0 || found == index.end())
          continue;
        const int j = found->second;
        double change = 0;
        for (int c = 0; c < n_voigt; ++c)
          change = std::max(change, std::abs(p1.stress[c][i] - p0.stress[c][j]));
        largest = std::max(largest, change);
        squares += change * change;
        compared += 1;
      }
    equilibration.max_stress_change = global_max(largest);
    equilibration.rms_stress_change = std::sqrt(global_sum(squares) / std::max(1.0, global_sum(compared)));
    equilibration.wall_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
    pcout << "  equilibration: " << equilibration.steps << " damped steps (D = "
          << parameters.initial_state.equilibration_damping << ") in " << equilibration.wall_seconds
          << " s; largest point speed at rest " << equilibration.final_speed << " m/s ("
          << equilibration.final_speed / equilibration.reference_speed
          << " sqrt(|g| H)); the stresses changed by up to " << equilibration.max_stress_change << " Pa (r.m.s. "
          << equilibration.rms_stress_change << " Pa)" << std::endl;
  }

  template void Simulator<2>::State::equilibrate();
  template void Simulator<3>::State::equilibrate();
} // namespace mpm
