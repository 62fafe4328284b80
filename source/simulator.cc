#include <mpm/core/migration.h>
#include <mpm/dealii/background_grid.h>
#include <mpm/dealii/checkpoint.h>
#include <mpm/dealii/cuda_engine.h>
#include <mpm/dealii/fem_state_file.h>
#include <mpm/dealii/guards.h>
#include <mpm/dealii/engine.h>
#include <mpm/dealii/material_points.h>
#include <mpm/dealii/output_writer.h>
#include <mpm/dealii/simulator.h>

#include <deal.II/base/conditional_ostream.h>
#include <deal.II/base/mpi.h>
#include <deal.II/base/timer.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <exception>
#include <future>
#include <iomanip>
#include <iostream>
#include <limits>
#include <sstream>
#include <unordered_map>
#include <utility>

namespace mpm
{
  using dealii::Utilities::MPI::max;
  using dealii::Utilities::MPI::min;
  using dealii::Utilities::MPI::sum;

  namespace
  {
    // Set by request_checkpoint_and_stop (a signal handler): lock-free, so async-signal-safe.
    std::atomic<bool> stop_requested{false};
    static_assert(std::atomic<bool>::is_always_lock_free);

    template <int dim>
    PointTotals<dim, double> global_totals(PointTotals<dim, double> t, MPI_Comm comm)
    {
      t.mass           = sum(t.mass, comm);
      t.kinetic_energy = sum(t.kinetic_energy, comm);
      t.n_points       = sum(t.n_points, comm);
      t.removed_mass   = sum(t.removed_mass, comm);
      t.n_removed      = sum(t.n_removed, comm);
      for (int d = 0; d < dim; ++d)
        {
          t.momentum[d] = sum(t.momentum[d], comm);
          t.lower[d]    = min(t.lower[d], comm);
          t.upper[d]    = max(t.upper[d], comm);
        }
      return t;
    }

    // Restores a stream's precision, which the summaries change, when it goes out of scope:
    // a program may run several simulations and print on the same stream.
    struct KeepPrecision
    {
      explicit KeepPrecision(std::ostream &stream)
        : stream(stream)
        , precision(stream.precision())
      {}
      ~KeepPrecision() { stream.precision(precision); }
      std::ostream         &stream;
      const std::streamsize precision;
    };

    // Largest elastic wave speed over the bodies, sqrt((K + 4G/3) / rho).
    double elastic_wave_speed(const Parameters &p)
    {
      double c = 0;
      for (unsigned int b = 0; b < p.bodies.size(); ++b)
        c = std::max(c, std::sqrt(p.materials[p.body_material[b]].elastic.p_wave_modulus() / p.bodies[b].density));
      return c;
    }

    // Deletes the run's TimerOutput, except while an exception unwinds the stack (an error on
    // its way to the user): there deal.II's destructor skips the timing summary (a collective
    // MPI call that not every rank might reach) and prints instead its seven-line banner
    // "TimerOutput objects finalize timed values printed to the screen by communicating over
    // MPI in their destructors..." ahead of the error's own message. The timer is then left
    // undestroyed on purpose: it holds no resource but memory, and the error ends the run.
    struct DeleteTimerUnlessUnwinding
    {
      void operator()(dealii::TimerOutput *timer) const
      {
        if (std::uncaught_exceptions() == 0)
          delete timer;
      }
    };

    // A step's largest speeds with "not a number" made infinite, so that the maximum over the
    // ranks (MPI_MAX may drop a NaN) and the stability check see it.
    StepReduction<double> nan_as_infinite(StepReduction<double> r)
    {
      for (double *speed : {&r.max_speed, &r.max_removed_speed})
        if (std::isnan(*speed))
          *speed = std::numeric_limits<double>::infinity();
      return r;
    }

    // The message of engine_step's stability check: the point that blew up (the first whose
    // velocity, position, stress, deformation gradient or volume is not finite, else the
    // fastest; on several ranks the worst over the ranks, a collective call), what blew up,
    // and the remedies that fit the scene's settings.
    template <int dim>
    std::string describe_instability(Engine<dim> &engine, const Parameters &p, const double c_el, const double dt,
                                     const double reported_speed, const bool equilibrating, const bool parallel,
                                     MPI_Comm communicator)
    {
      const auto num = [](const double v) {
        std::ostringstream s;
        s.precision(4);
        s << v;
        return s.str();
      };
      PointSnapshot<dim> snapshot;
      engine.snapshot(snapshot);
      const HostPoints<dim, double> &x = snapshot.points;
      const auto finite = [](const double v) { return std::isfinite(v); };
      int         worst = -1, broken = -1;
      std::string quantity;
      double      fastest = -1;
      for (int i = 0; i < x.size() && broken < 0; ++i)
        {
          double v2 = 0;
          for (int d = 0; d < dim; ++d)
            v2 += x.velocity[d][i] * x.velocity[d][i];
          const auto all = [&](const auto &arrays, const int n) {
            for (int c = 0; c < n; ++c)
              if (!finite(arrays[c][i]))
                return false;
            return true;
          };
          quantity = !all(x.velocity, dim)                  ? "velocity" :
                     !all(x.position, dim)                  ? "position" :
                     !all(x.stress, n_voigt)                ? "stress" :
                     !all(x.deformation_gradient, dim * dim) ? "deformation gradient" :
                     !finite(x.volume[i])                   ? "volume" :
                                                              "";
          if (!quantity.empty())
            broken = worst = i;
          else if (std::sqrt(v2) > fastest)
            {
              fastest = std::sqrt(v2);
              worst   = i;
            }
        }

      const auto vector = [&](const auto &arrays, const int i) {
        std::string s = "(";
        for (int d = 0; d < dim; ++d)
          s += (d ? ", " : "") + num(arrays[d][i]);
        return s + ")";
      };
      std::string point = "no point";
      if (worst >= 0)
        {
          const int m = x.material[worst];
          point = "material point " + std::to_string(snapshot.labels->id[worst]) +
                  (m >= 0 ? " of material '" + p.material_names[m] + "' (" + p.material_models[m] + ")" :
                            std::string(", which left the grid in this step,")) +
                  " at " + vector(x.position, worst) + " (it started at " +
                  vector(snapshot.labels->initial_position, worst) + ")" +
                  (parallel ? " on MPI rank " + std::to_string(dealii::Utilities::MPI::this_mpi_process(communicator)) :
                              std::string()) +
                  ": " +
                  (broken >= 0 ? "its " + quantity + " is not a finite number (velocity " +
                                   vector(x.velocity, worst) + " m/s)" :
                                 "it moves at " + num(fastest) + " m/s, " + num(fastest / c_el) +
                                   " times the elastic wave speed " + num(c_el) + " m/s");
        }
      if (parallel)
        {
          // The worst over the ranks: a broken point first, then the fastest (the lowest rank on a tie).
          const double rank_score = broken >= 0 ? std::numeric_limits<double>::infinity() : fastest;
          const std::vector<double> scores = dealii::Utilities::MPI::all_gather(communicator, rank_score);
          const std::vector<std::string> points = dealii::Utilities::MPI::all_gather(communicator, point);
          const auto best = std::max_element(scores.begin(), scores.end()) - scores.begin();
          point           = points[best];
          broken          = scores[best] == std::numeric_limits<double>::infinity() ? 0 : -1;
          fastest         = scores[best];
        }
      // The fastest point may have left the grid in this step and be gone (on several ranks
      // the re-sort drops such points): say so before naming the fastest of those left.
      if (broken < 0 && std::isfinite(reported_speed) && fastest < 0.5 * reported_speed)
        point = "a point that left the grid in this step moved at " + num(reported_speed) + " m/s (" +
                num(reported_speed / c_el) + " times the elastic wave speed " + num(c_el) +
                " m/s); of the points left, the fastest is " + point;

      // What to change, as fits the scene.
      std::vector<std::string> advice;
      if (!(c_el > 0 && std::isfinite(c_el)))
        advice.push_back("the elastic wave speed c_el = " + num(c_el) +
                         " m/s that sets the time step is not a positive number: check the materials' Young's "
                         "modulus and Poisson's ratio and the bodies' Density");
      if (p.adaptive_time_step)
        advice.push_back("reduce Solver/CFL number (now " + num(p.cfl) + ")");
      else
        advice.push_back("reduce Solver/Fixed time step (now " + num(p.fixed_time_step) +
                         " s; the elastic limit h / c_el is " + num(p.cell_size / c_el) + " s, the last step " +
                         num(dt) + " s)");
      if (p.scheme == UpdateScheme::usl)
        advice.push_back("use Solver/Update scheme = MUSL (USL is the least stable where nodes carry little mass)");
      if (p.shape_function == ShapeFunction::linear)
        advice.push_back("use Solver/Shape function = GIMP (linear shape functions jump as points cross cells)");
      if (!equilibrating && !(p.damping > 0))
        advice.push_back("add Solver/Local damping (now 0; 0.05 to 0.1 calms a dynamic start)");
      if (p.flip_fraction >= 1)
        advice.push_back("blend in some PIC (Solver/FLIP fraction below 1, e.g. 0.99) against velocity noise");
      if (broken >= 0 && quantity != "velocity" && quantity != "position" && !parallel)
        advice.push_back("check the material's parameters: its " + quantity + " failed first");
      std::string remedies;
      for (std::size_t k = 0; k < advice.size(); ++k)
        remedies += (k == 0 ? "" : k + 1 == advice.size() ? "; or " : "; ") + advice[k];
      return point + ". " + (remedies.empty() ? std::string() : "To stabilise it: " + remedies + ".");
    }
  } // namespace

  // Everything a run holds between its steps. Members are destroyed in reverse order: the
  // output (whose background tasks read the grid) before the grid, points and engine; the
  // timer last but for the stream it prints to.
  template <int dim>
  struct Simulator<dim>::State
  {
    State(const Parameters &p, MPI_Comm comm)
      : parameters(p)
      , communicator(comm)
      , n_ranks(dealii::Utilities::MPI::n_mpi_processes(comm))
      , parallel(n_ranks > 1)
      , pcout(std::cout, dealii::Utilities::MPI::this_mpi_process(comm) == 0)
      , timer_owner(new dealii::TimerOutput(comm, pcout, dealii::TimerOutput::summary, dealii::TimerOutput::wall_times))
      , timer(*timer_owner)
      , wall_start(std::chrono::steady_clock::now())
    {}

    struct GridAndPoints
    {
      std::unique_ptr<BackgroundGrid<dim>> grid;
      std::unique_ptr<MaterialPoints<dim>> points;
      double                               seconds = 0;
    };

    const Parameters           parameters;
    MPI_Comm                   communicator;
    const unsigned int         n_ranks;
    const bool                 parallel;
    dealii::ConditionalOStream pcout;
    std::unique_ptr<dealii::TimerOutput, DeleteTimerUnlessUnwinding> timer_owner;
    dealii::TimerOutput                                             &timer;
    const std::chrono::steady_clock::time_point wall_start;
    std::chrono::steady_clock::time_point       stepping_start; // the end of setup()

    double c_el = 0, h = 0;
    std::unique_ptr<BackgroundGrid<dim>> grid;
    std::unique_ptr<MaterialPoints<dim>> points;
    std::unique_ptr<Engine<dim>>         engine;
    std::unique_ptr<OutputWriter<dim>>   output;
    std::vector<MaterialParameters<double>> materials;
    bool                                    plastic = false;
    StepSettings<dim, double>               settings;

    long   n_points_initial = 0;
    double m_min            = 1e300;
    // The loss checks (check_losses): the initial mass, and on this rank the points dropped
    // from the engine after leaving the grid (re-sorts), their number and mass; the largest
    // relative mass balance seen.
    double initial_mass = 0, dropped_mass = 0, worst_mass_balance = 0;
    long   n_dropped    = 0;
    // One rank: deal.II's grid and handler being built on a thread (see setup()).
    std::future<GridAndPoints> grid_build;
    const std::string          beside_grid          = "setup and first steps, beside deal.II's grid";
    double                     engine_setup_seconds = 0;
    bool                       initial_output_pending = false;

    double resort_at = 1e300;
    long   n_resorts = 0, n_repartitions = 0;
    double balanced  = 1; // imbalance right after the last repartition: what p4est achieves

    double time = 0, max_speed = 0, max_removed_speed = 0, work_of_gravity = 0, dt = 0, gravity_power = 0;
    bool                equilibrating = false;
    EquilibrationReport equilibration;
    long   step = 0, n_removed = 0;
    double next_output = 0;
    std::chrono::steady_clock::time_point last_progress;
    bool set_up = false, finished_run = false;

    // Checkpoints: when the last was written (wall clock, step), and what was asked for after
    // the last step, agreed by every rank: 0 nothing, 1 a checkpoint (wall clock due), 2 a
    // checkpoint and a stop (request_checkpoint_and_stop).
    std::chrono::steady_clock::time_point last_checkpoint_wall;
    long                                  last_checkpoint_step = -1;
    std::string                           last_checkpoint;
    int                                   request = 0;
    bool                                  stopped = false;
    // Where this process started stepping (a resumed run: the checkpoint's time and step),
    // for its rates and ETA.
    double first_time = 0;
    long   first_step = 0;

    // What this rank asks for after the current step (request): 2 stop, 1 a checkpoint.
    int local_request() const
    {
      if (stop_requested.load())
        return 2;
      const double minutes =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - last_checkpoint_wall).count() / 60;
      return parameters.checkpoint_wall_interval > 0 && minutes >= parameters.checkpoint_wall_interval ? 1 : 0;
    }

    // Reductions over the ranks; on one rank the value itself, without an MPI call.
    double global_max(const double x) const { return parallel ? max(x, communicator) : x; }
    double global_min(const double x) const { return parallel ? min(x, communicator) : x; }
    double global_sum(const double x) const { return parallel ? sum(x, communicator) : x; }

    // A TimerOutput section, except while the grid thread runs (then the time counts to
    // the section entered before it started).
    template <typename Work>
    auto timed(const char *section, Work &&work)
    {
      if (grid_build.valid())
        return work();
      dealii::TimerOutput::Scope scope(timer, section);
      return work();
    }

    // Joins the grid thread (waits for it where it is still running): from here on the
    // grid and the handler exist and MPI may be called again.
    void join_grid()
    {
      if (!grid_build.valid())
        return;
      GridAndPoints built = grid_build.get();
      grid                = std::move(built.grid);
      points              = std::move(built.points);
      timer.leave_subsection(beside_grid);
      pcout << "  deal.II's grid and ParticleHandler built on a thread in " << built.seconds
            << " s, beside the engine's set-up (" << engine_setup_seconds << " s) and the first " << step
            << " steps" << std::endl;
      if (initial_output_pending)
        {
          dealii::TimerOutput::Scope scope(timer, "output");
          output->write_fields(0, *grid); // before the first step every nodal field is zero
          initial_output_pending = false;
        }
    }

    // Max/mean work per rank; the engine knows its points where it re-sorts them itself.
    double imbalance() const
    {
      return engine ? points->imbalance(static_cast<double>(engine->n_points())) : points->imbalance();
    }

    // Repartition when the work per rank is out of balance by more than the threshold and
    // by clearly more than the last repartition could reach (no futile repeats when the
    // granularity of cells forbids better). Points per rank only change at re-sorts, so
    // this is checked at the start and after each re-sort.
    bool balance()
    {
      if (!parallel || !(parameters.load_balance_threshold > 0))
        return false;
      const double before = imbalance();
      if (before <= parameters.load_balance_threshold ||
          before <= balanced + 0.5 * (parameters.load_balance_threshold - 1))
        return false;
      dealii::TimerOutput::Scope scope(timer, "repartition");
      output->finish(); // a grid output in flight reads the DoFHandler
      if (engine)
        engine->sync(*points); // the handler's points move with their cells
      points->repartition();
      ++n_repartitions;
      balanced = points->imbalance();
      pcout << "  repartitioned the grid by work: max/mean work per rank " << before << " -> " << balanced
            << std::endl;
      return true;
    }

    // Plastic models answer elastically until Solver/Plasticity start time.
    void switch_plasticity_on_when_due()
    {
      if (plastic || time < parameters.plasticity_start_time)
        return;
      plastic = true;
      for (auto &m : materials)
        m.plasticity_enabled = true;
      engine->set_materials(materials);
      pcout << "  plasticity switched on at t = " << time << " s" << std::endl;
    }

    // One step of the engine with the current settings, and what every step needs after it:
    // the largest speeds over the ranks, the MPI re-sort when points have strayed, the
    // stability check. Time and step counters are the caller's.
    void engine_step(const double dt)
    {
      const StepReduction<double> r = nan_as_infinite(timed("MPM step", [&]() { return engine->step(settings, dt); }));
      gravity_power     = r.gravity_power;
      max_speed         = r.max_speed;
      max_removed_speed = r.max_removed_speed;
      // Where a message says the step was; built only for a message (a string per step costs).
      const auto when = [&]() {
        return equilibrating ?
                 "in damped step " + std::to_string(equilibration.steps + 1) + " of the equilibration" :
                 "at t = " + dealii::Utilities::to_string(time + dt) + " s (step " + std::to_string(step + 1) + ")";
      };
      if (parallel)
        {
          // One reduction for the next time step and the migration test: the largest
          // speed and the largest distance of a point outside its home cell.
          // And what the ranks ask for after the step (a checkpoint, a stop).
          double local[4] = {r.max_speed, engine->max_distance_outside_home_cells(), r.max_removed_speed,
                             double(local_request())},
                 global[4];
          dealii::Utilities::MPI::max(dealii::ArrayView<const double>(local, 4), communicator,
                                      dealii::ArrayView<double>(global, 4));
          max_speed         = global[0];
          max_removed_speed = global[2];
          request           = static_cast<int>(global[3]);
          AssertThrow(!parameters.pressure_averaging || global[1] < 1,
                      dealii::ExcMessage("Parameter 'Solver/Pressure averaging': " + when() + " a point moved to " +
                                         dealii::Utilities::to_string(global[1]) +
                                         " cells outside the cell it was sorted into, beyond the ghost cells "
                                         "whose pressure sums are exchanged between ranks. Reduce 'Solver/CFL "
                                         "number' or the time step."));
          if (global[1] >= resort_at)
            {
              {
                dealii::TimerOutput::Scope scope(timer, "migrate points");
                resort();
              }
              if (balance())
                engine->load(*points);
            }
        }
      // A blow-up shows as a non-finite velocity or, with the adaptive step, as speeds that
      // shrink dt by orders of magnitude: stop with a message instead of crawling on.
      // (Every rank decides alike: the speeds are the maxima over the ranks.)
      const double fastest = std::max(max_speed, max_removed_speed);
      if (!(std::isfinite(fastest) && fastest <= 1000 * c_el))
        AssertThrow(false, dealii::ExcMessage("The simulation became unstable " + when() + " (a speed above 1000 "
                                              "times the elastic wave speed, or not finite): " +
                                              describe_instability<dim>(*engine, parameters, c_el, dt, fastest,
                                                                        equilibrating, parallel, communicator)));
    }

    // Initial state/Equilibrate: damped steps at t = 0 with gravity in full until the points
    // rest in the MPM's own equilibrium of the state given (time and step stay 0).
    void equilibrate()
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
      settings.damping       = parameters.equilibration_damping;
      settings.flip_fraction = 0;
      settings.hold_points   = true;
      equilibrating          = true;
      double calm            = 0; // how long the points have been at rest
      while (calm < transit)
        {
          AssertThrow(equilibration.steps < long(parameters.equilibration_maximum_steps),
                      dealii::ExcMessage(
                        "Parameter 'Initial state/Equilibration maximum steps': after " +
                        std::to_string(equilibration.steps) + " damped steps the largest point speed is still " +
                        dealii::Utilities::to_string(max_speed / equilibration.reference_speed) +
                        " sqrt(|g| H), above 'Initial state/Equilibration tolerance' (" +
                        dealii::Utilities::to_string(parameters.equilibration_tolerance) +
                        "). Either the state is not stable under these materials (it fails under its own "
                        "weight), or it needs more steps: raise the maximum or the tolerance."));
          const double dt = parameters.adaptive_time_step ?
                              std::min(parameters.cfl, courant) * h / (c_el + max_speed) :
                              std::min(parameters.fixed_time_step, courant * h / c_el);
          settings.hold_from_point_momentum = !on_grid || equilibration.steps == 0;
          engine_step(dt);
          ++equilibration.steps;
          calm = max_speed < parameters.equilibration_tolerance * equilibration.reference_speed ? calm + dt : 0;
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
            << parameters.equilibration_damping << ") in " << equilibration.wall_seconds
            << " s; largest point speed at rest " << equilibration.final_speed << " m/s ("
            << equilibration.final_speed / equilibration.reference_speed
            << " sqrt(|g| H)); the stresses changed by up to " << equilibration.max_stress_change << " Pa (r.m.s. "
            << equilibration.rms_stress_change << " Pa)" << std::endl;
    }

    // The step's settings from the prm (gravity is set by each step, from the ramp).
    void apply_settings()
    {
      settings.scheme             = parameters.scheme;
      settings.damping            = parameters.damping;
      settings.damping_form       = parameters.damping_form;
      settings.damping_threshold  = parameters.damping_threshold;
      settings.flip_fraction      = parameters.flip_fraction;
      settings.domain_update      = parameters.domain_update;
      settings.pressure_averaging = parameters.pressure_averaging;
      settings.mass_tolerance     = 1e-12 * m_min; // nodes lighter than that carry no velocity
    }

    void print_header()
    {
      const HostGrid<dim, double> lattice = lattice_geometry<dim>(parameters);
      long                        n_cells = 1, n_nodes = 1;
      for (int d = 0; d < dim; ++d)
        {
          n_cells *= lattice.n_cells[d];
          n_nodes *= lattice.n_cells[d] + 1;
        }
      pcout << "dealii-mpm: " << dim << "D, " << n_cells << " cells, " << n_nodes << " nodes, " << n_points_initial
            << " material points, " << n_ranks << " MPI rank(s), backend " << parameters.backend << "\n"
            << "  elastic wave speed " << c_el << " m/s, end time " << parameters.end_time << " s, output in '"
            << output->directory() << "'" << std::endl;
    }

    // Everything of the run but its points and grid, for a checkpoint (collective: the
    // points handed between ranks are summed).
    RunState run_state() const
    {
      RunState r;
      r.dim                  = dim;
      r.n_ranks              = n_ranks;
      r.lower                = parameters.lower;
      r.upper                = parameters.upper;
      r.cell_size            = parameters.cell_size;
      r.n_materials          = parameters.materials.size();
      r.state_variable_names = parameters.state_variable_names();
      r.time                 = time;
      r.dt                   = dt;
      r.max_speed            = max_speed;
      r.max_removed_speed    = max_removed_speed;
      r.work_of_gravity      = work_of_gravity;
      r.elastic_wave_speed   = c_el;
      r.smallest_point_mass  = m_min;
      r.balanced             = balanced;
      r.next_output          = next_output;
      r.step                 = step;
      r.n_points_initial     = n_points_initial;
      r.n_removed            = n_removed;
      r.initial_mass         = initial_mass;
      r.n_dropped            = parallel ? static_cast<long>(sum(double(n_dropped), communicator)) : n_dropped;
      r.dropped_mass         = parallel ? sum(dropped_mass, communicator) : dropped_mass;
      r.n_resorts            = n_resorts;
      r.n_repartitions       = n_repartitions;
      r.n_sent               = parallel ? static_cast<long>(sum(double(points->n_sent), communicator)) : 0;
      r.plastic              = plastic;
      r.equilibration        = equilibration;
      const auto records     = output->records();
      r.n_outputs            = records.n_outputs;
      r.grid_records         = records.grid;
      r.particle_records     = records.particles;
      return r;
    }

    // Several ranks: the partition of the grid by the points' work as it is now (where the
    // run repartitions at all). A pure function of the points' cells, whichever partition the
    // grid had before: a run resumed on an even partition comes to the same one.
    void partition_by_current_work()
    {
      if (!parallel || !(parameters.load_balance_threshold > 0))
        return;
      output->finish(); // a grid output in flight reads the DoFHandler
      points->repartition();
      ++n_repartitions;
      balanced = points->imbalance();
    }

    // A checkpoint of the run after the current step. Then the engine starts anew from the
    // saved points exactly as a run resumed from the checkpoint does (on several ranks: the
    // handler filled with them, the grid partitioned by their work, the engine loaded from
    // the handler; on one: the engine loaded with them, forgetting what it built for the
    // points before, the CPU's scatter slabs): the resumed run is bit-identical to this one.
    std::string write_checkpoint()
    {
      join_grid();
      dealii::TimerOutput::Scope scope(timer, "checkpoint");
      const auto                 started = std::chrono::steady_clock::now();
      PointSnapshot<dim>         snapshot;
      if (parallel)
        {
          resort(); // every point on the rank owning its cell
        }
      engine->snapshot(snapshot);
      last_checkpoint = checkpoint::write<dim>(parameters.checkpoint_directory, run_state(), snapshot,
                                               parameters.checkpoint_keep, communicator);
      start_from(snapshot);
      last_checkpoint_wall = std::chrono::steady_clock::now();
      last_checkpoint_step = step;
      pcout << "  checkpoint at t = " << time << " s (step " << step << "): " << last_checkpoint << " ("
            << std::chrono::duration<double>(last_checkpoint_wall - started).count() << " s)" << std::endl;
      return last_checkpoint;
    }

    // The engine (made where there is none yet) starts from `saved`: a checkpoint's points,
    // all of this rank's (one rank) or those in its cells (several).
    void start_from(const PointSnapshot<dim> &saved)
    {
      if (parallel)
        {
          points->replace(saved);
          partition_by_current_work();
          if (!engine)
            engine = make_engine<dim>(parameters.backend, *grid, materials, parameters.shape_function);
          engine->load(*points);
        }
      else
        {
          if (!engine)
            engine = make_engine<dim>(parameters.backend, lattice_grid<dim>(parameters), materials,
                                      parameters.shape_function);
          engine->load(saved.points, saved.labels); // in the saved order: the same sums as before
        }
      engine->set_sort_interval(parameters.sort_interval);
    }

    // The MPI re-sort, counting the points it drops (those that left the grid): they must be
    // the ones the engine held as removed.
    void resort()
    {
      const PointTotals<dim, double> held    = engine->totals();
      const unsigned int             dropped = engine->resort(*points);
      AssertThrow(static_cast<long>(dropped) == held.n_removed,
                  dealii::ExcMessage("Internal error (loss check): a re-sort dropped " + std::to_string(dropped) +
                                     " points, but " + std::to_string(held.n_removed) +
                                     " had left the grid on this rank."));
      n_dropped += held.n_removed;
      dropped_mass += held.removed_mass;
      ++n_resorts;
    }

    // Points are never made or lost but by leaving the grid: the points in the grid and those
    // removed make the initial number exactly, and their masses the initial mass to round-off
    // (1e-9: the sums' order differs). Throws where either fails: a bug, not a bad input.
    // Returns (removed mass, relative mass balance).
    std::pair<double, double> check_losses(const PointTotals<dim, double> &totals)
    {
      double       local[2] = {double(n_dropped), dropped_mass}, global[2] = {local[0], local[1]};
      if (parallel)
        dealii::Utilities::MPI::sum(dealii::ArrayView<const double>(local, 2), communicator,
                                    dealii::ArrayView<double>(global, 2));
      const long   removed      = totals.n_removed + static_cast<long>(global[0]);
      const double removed_mass = totals.removed_mass + global[1];
      const double balance      = (totals.mass + removed_mass - initial_mass) / initial_mass;
      n_removed                 = removed;
      worst_mass_balance        = std::max(worst_mass_balance, std::abs(balance));
      const std::string when    = " at t = " + dealii::Utilities::to_string(time) + " s (step " + std::to_string(step) + ")";
      AssertThrow(totals.n_points + removed == n_points_initial,
                  dealii::ExcMessage("Internal error (loss check)" + when + ": " + std::to_string(totals.n_points) +
                                     " material points in the grid and " + std::to_string(removed) +
                                     " removed make " + std::to_string(totals.n_points + removed) + ", not the " +
                                     std::to_string(n_points_initial) + " the run started with."));
      AssertThrow(std::abs(balance) <= 1e-9,
                  dealii::ExcMessage("Internal error (loss check)" + when + ": the mass in the grid (" +
                                     dealii::Utilities::to_string(totals.mass) + " kg) and the mass removed (" +
                                     dealii::Utilities::to_string(removed_mass) + " kg) differ from the initial " +
                                     dealii::Utilities::to_string(initial_mass) + " kg by a relative " +
                                     dealii::Utilities::to_string(balance) + ", beyond round-off (1e-9)."));
      return {removed_mass, balance};
    }

    void record_history()
    {
      timed("history", [&]() {
        const auto local  = engine->totals();
        const auto totals = parallel ? global_totals<dim>(local, communicator) : local;
        const auto [removed_mass, balance] = check_losses(totals);
        typename OutputWriter<dim>::HistoryRow row{time, dt, work_of_gravity, step, n_removed, totals};
        row.removed_mass = removed_mass;
        row.mass_balance = balance;
        row.min_points_per_rank = static_cast<long>(global_min(double(local.n_points)));
        row.max_points_per_rank = static_cast<long>(global_max(double(local.n_points)));
        row.n_resorts           = n_resorts;
        row.n_repartitions      = n_repartitions;
        row.n_sent              = parallel ? static_cast<long>(sum(double(points->n_sent), communicator)) : 0;
        output->write_history(row);
      });
    }

    // Output reads a snapshot of the engine's points: no hand-over to the handler, which
    // is brought up to date only where it is needed (re-sorts, repartitions).
    void write_output()
    {
      if (time == 0 && grid_build.valid())
        {
          engine->snapshot(output->next_snapshot());
          initial_output_pending = true;
          return;
        }
      join_grid();
      dealii::TimerOutput::Scope scope(timer, "output");
      engine->snapshot(output->next_snapshot());
      engine->nodal_to(*grid);
      output->write_fields(time, *grid);
    }
  };

  template <int dim>
  Simulator<dim>::Simulator(const Parameters &parameters, MPI_Comm communicator)
    : state(std::make_unique<State>(parameters, communicator))
  {
    check_memory(parameters, communicator); // before anything large is allocated
  }

  template <int dim>
  Simulator<dim>::~Simulator() = default;

  namespace
  {
    // The elastic wave speed of points given to setup(): the largest over the points of
    // sqrt(M / rho), rho = mass / volume of the point.
    template <int dim>
    double elastic_wave_speed(const std::vector<GeneratedBody<dim>> &bodies, const Parameters &p)
    {
      double c = 0;
      for (const GeneratedBody<dim> &body : bodies)
        for (int i = 0; i < body.points.size(); ++i)
          c = std::max(c, std::sqrt(p.materials[body.points.material[i]].elastic.p_wave_modulus() *
                                    body.points.volume[i] / body.points.mass[i]));
      return c;
    }

    // Points handed over on several ranks come from each rank's own FEM cells. Every rank
    // needs all of them (it keeps those in its MPM cells, as with the prm's bodies, which
    // every rank generates whole), in one order on every rank: rank by rank.
    template <int dim>
    std::vector<GeneratedBody<dim>> gather_bodies(const std::vector<GeneratedBody<dim>> &local, MPI_Comm comm)
    {
      std::vector<double> packed; // per body: its numbers of points and state variables, every array
      for (const GeneratedBody<dim> &body : local)
        {
          packed.push_back(body.points.size());
          packed.push_back(body.points.n_state_variables());
          for_each_point_array<dim>(body.points, body.points,
                                    [&](const auto &array, const auto &) { packed.insert(packed.end(), array.begin(), array.end()); });
        }
      std::vector<GeneratedBody<dim>> all;
      for (const std::vector<double> &from_rank : dealii::Utilities::MPI::all_gather(comm, packed))
        for (std::size_t at = 0; at < from_rank.size();)
          {
            GeneratedBody<dim> body;
            const int          n_points = static_cast<int>(from_rank[at++]);
            body.points.set_n_state_variables(static_cast<int>(from_rank[at++]));
            body.points.resize(n_points);
            for_each_point_array<dim>(body.points, body.points, [&](auto &array, auto &) {
              using T = typename std::decay_t<decltype(array)>::value_type;
              for (auto &value : array)
                value = static_cast<T>(from_rank[at++]);
            });
            all.push_back(std::move(body));
          }
      return all;
    }

    // The points handed over as one body, ordered by position (lexicographically, x first):
    // their ids (the order of generation) then do not depend on how the FEM mesh was
    // distributed over the ranks.
    template <int dim>
    std::vector<GeneratedBody<dim>> in_canonical_order(const std::vector<GeneratedBody<dim>> &bodies)
    {
      std::vector<std::pair<int, int>> source; // (body, point)
      for (unsigned int b = 0; b < bodies.size(); ++b)
        for (int i = 0; i < bodies[b].points.size(); ++i)
          source.emplace_back(b, i);
      auto position = [&](const std::pair<int, int> &s, const int d) {
        return bodies[s.first].points.position[d][s.second];
      };
      std::stable_sort(source.begin(), source.end(), [&](const auto &a, const auto &b) {
        for (int d = 0; d < dim; ++d)
          if (position(a, d) != position(b, d))
            return position(a, d) < position(b, d);
        return false;
      });
      // Two points at one position: the same FEM cells handed over twice, typically a serial
      // Triangulation handed over by every rank of a run.
      for (std::size_t k = 1; k < source.size(); ++k)
        {
          bool same = true;
          for (int d = 0; d < dim; ++d)
            same = same && position(source[k - 1], d) == position(source[k], d);
          AssertThrow(!same, dealii::ExcMessage(
                               "Simulator::setup(bodies): two points handed over at the same position (" +
                               std::to_string(position(source[k], 0)) + ", " + std::to_string(position(source[k], 1)) +
                               ", ...). On several MPI ranks each rank must hand over only its own cells: a "
                               "parallel::distributed::Triangulation, or a serial mesh handed over by one rank."));
        }
      std::vector<GeneratedBody<dim>> one(1);
      HostPoints<dim, double>        &to = one[0].points;
      for (const GeneratedBody<dim> &body : bodies) // an empty body (a rank without cells) may hold none
        if (body.points.size() > 0)
          to.set_n_state_variables(body.points.n_state_variables());
      to.resize(static_cast<int>(source.size()));
      for (std::size_t k = 0; k < source.size(); ++k)
        for_each_point_array<dim>(to, bodies[source[k].first].points,
                                  [&](auto &destination, const auto &origin) { destination[k] = origin[source[k].second]; });
      return one;
    }

    // Points given to setup() carry the state variables of the run's models (an empty body,
    // from a rank without FEM cells, may carry none).
    template <int dim>
    void check_state_variable_count(const std::vector<GeneratedBody<dim>> &bodies, const Parameters &p)
    {
      const std::vector<std::string> names = p.state_variable_names();
      for (const GeneratedBody<dim> &body : bodies)
        AssertThrow(body.points.size() == 0 || body.points.n_state_variables() == static_cast<int>(names.size()),
                    dealii::ExcMessage("The material points handed over: " +
                                       state_variable_count_mismatch(body.points.n_state_variables(), names)));
    }

    // Points given to setup(): inside the grid, a material of the prm, a positive mass and volume.
    template <int dim>
    void check_given_points(const std::vector<GeneratedBody<dim>> &bodies, const Parameters &p)
    {
      long n = 0;
      for (const GeneratedBody<dim> &body : bodies)
        for (int i = 0; i < body.points.size(); ++i, ++n)
          {
            std::string where = "point " + std::to_string(n) + " at (";
            bool        inside = true;
            for (int d = 0; d < dim; ++d)
              {
                const double x = body.points.position[d][i];
                where += (d ? ", " : "") + dealii::Utilities::to_string(x);
                inside = inside && x >= p.lower[d] && x <= p.upper[d];
              }
            where += ")";
            AssertThrow(inside, dealii::ExcMessage("The material points handed over: " + where +
                                                   " lies outside the MPM grid (Grid/Lower corner, Grid/Upper "
                                                   "corner); make the grid enclose the body and its run-out."));
            const int m = body.points.material[i];
            AssertThrow(m >= 0 && m < static_cast<int>(p.materials.size()),
                        dealii::ExcMessage("The material points handed over: " + where + " has material index " +
                                           std::to_string(m) + ", but Materials/Names declares " +
                                           std::to_string(p.materials.size()) + " material(s), indices 0 to " +
                                           std::to_string(p.materials.size() - 1) + "."));
            AssertThrow(body.points.mass[i] > 0 && body.points.volume[i] > 0,
                        dealii::ExcMessage("The material points handed over: " + where +
                                           " has a mass or volume that is not positive."));
            AssertThrow(p.materials[m].field_parameter == FieldParameter::none,
                        dealii::ExcMessage("The material points handed over: material '" + p.material_names[m] +
                                           "' has a random field (Material " + p.material_names[m] +
                                           "/Random field), which points handed over do not carry yet; set its "
                                           "Parameter to none."));
          }
      AssertThrow(n > 0, dealii::ExcMessage("The material points handed over: there are none."));
    }
  } // namespace

  template <int dim>
  void Simulator<dim>::setup()
  {
    setup(false, nullptr);
  }

  template <int dim>
  void Simulator<dim>::setup(std::vector<GeneratedBody<dim>> bodies)
  {
    setup(false, &bodies);
  }

  template <int dim>
  void Simulator<dim>::setup(const bool grid_beside_first_steps, std::vector<GeneratedBody<dim>> *given_bodies)
  {
    State            &s          = *state;
    const Parameters &parameters = s.parameters;
    AssertThrow(!s.set_up, dealii::ExcMessage("Simulator::setup() was called twice."));
    s.h    = parameters.cell_size;
    if (given_bodies != nullptr)
      {
        if (s.parallel)
          *given_bodies = gather_bodies(*given_bodies, s.communicator);
        check_state_variable_count(*given_bodies, parameters);
        *given_bodies = in_canonical_order(*given_bodies);
        check_given_points(*given_bodies, parameters);
        // GIMP's particle domains stay within half a cell, and inside the grid: a domain that
        // reached beyond the grid's face would lose the weight of the nodes beyond it.
        for (GeneratedBody<dim> &body : *given_bodies)
          for (int d = 0; d < dim; ++d)
            for (int i = 0; i < body.points.size(); ++i)
              {
                const double x     = body.points.position[d][i];
                const double limit = std::min({0.5 * s.h, x - parameters.lower[d], parameters.upper[d] - x});
                const double scale = std::min(1.0, limit / body.points.domain_half_length[d][i]);
                body.points.domain_half_length[d][i] *= scale;
                body.points.initial_domain_half_length[d][i] *= scale;
              }
        s.c_el = elastic_wave_speed(*given_bodies, parameters);
      }
    else
      s.c_el = elastic_wave_speed(parameters);
    if (!parameters.adaptive_time_step)
      AssertThrow(parameters.fixed_time_step * s.c_el <= s.h,
                  dealii::ExcMessage("Parameter 'Solver/Fixed time step': " +
                                     dealii::Utilities::to_string(parameters.fixed_time_step) +
                                     " s exceeds the elastic stability limit h / c_el = " +
                                     dealii::Utilities::to_string(s.h / s.c_el) + " s (CFL > 1)."));
    check_backend(parameters.backend); // before any set-up

    // Set-up. The CUDA context is created on a thread of its own (0.3-0.5 s on the GPU
    // host) and the bodies' points on another (they need the lattice only).
    std::future<void> cuda_ready;
    if (parameters.backend == "cuda")
      cuda_ready = start_cuda_initialisation(s.communicator);
    std::shared_future<std::vector<GeneratedBody<dim>>> generation;
    if (given_bodies != nullptr)
      {
        std::promise<std::vector<GeneratedBody<dim>>> given;
        given.set_value(std::move(*given_bodies));
        generation = given.get_future().share();
      }
    else
      generation =
        std::async(std::launch::async, [&parameters]() { return generate_bodies<dim>(parameters); }).share();
    s.output = std::make_unique<OutputWriter<dim>>(parameters, s.communicator); // MPI: before the grid thread
    // Before plasticity start time every model behaves elastically.
    s.materials = parameters.materials;
    s.plastic   = !(parameters.plasticity_start_time > 0);
    for (auto &m : s.materials)
      m.plasticity_enabled = s.plastic;

    // Every rank generates every body, so these need no communication.
    auto count_points = [&]() {
      for (const GeneratedBody<dim> &body : generation.get())
        {
          s.n_points_initial += body.points.size();
          for (const double m : body.points.mass)
            {
              s.m_min = std::min(s.m_min, m);
              s.initial_mass += m;
            }
          // The first adaptive time step heeds the bodies' initial velocity (after a step
          // the step's own largest speed does).
          for (int i = 0; i < body.points.size(); ++i)
            {
              double v2 = 0;
              for (int d = 0; d < dim; ++d)
                v2 += body.points.velocity[d][i] * body.points.velocity[d][i];
              s.max_speed = std::max(s.max_speed, std::sqrt(v2));
            }
        }
      AssertThrow(s.n_points_initial > 0,
                  dealii::ExcMessage("Parameter 'Material points': the bodies contain no material point (each "
                                     "body must cover at least one point site of the grid)."));
    };

    // One rank: the engine keeps its own nodes on the lattice and starts from the bodies,
    // so the steps can start while deal.II builds the grid and fills the ParticleHandler on
    // a thread (0.6-1.4 s of the 3D collapse's set-up on the GPU host). deal.II initialises
    // MPI for serialized calls only, and that thread calls MPI (the Partitioner, the
    // handler's counts); until it is joined this thread calls none: no reduction over one
    // rank, no TimerOutput section (its timers call MPI_Comm_size) except the one entered
    // before the thread starts and left after it is joined, and no output (which needs the
    // grid: the t = 0 output is written once it exists, a later one waits for it). Where a
    // user's program steps the run, it may call MPI between the steps: the grid is joined
    // at the end of setup().
    if (!s.parallel)
      {
        s.timer.enter_subsection(s.beside_grid);
        s.grid_build = std::async(std::launch::async, [&parameters, comm = s.communicator, generation]() {
          const auto                     start = std::chrono::steady_clock::now();
          typename State::GridAndPoints built;
          built.grid   = std::make_unique<BackgroundGrid<dim>>(parameters, comm);
          built.points = std::make_unique<MaterialPoints<dim>>(*built.grid, parameters);
          built.points->insert(generation.get());
          built.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
          return built;
        });
        const auto start = std::chrono::steady_clock::now();
        count_points();
        HostPoints<dim, double> host;
        auto                    labels = std::make_shared<PointLabels<dim>>();
        points_of_bodies(generation.get(), lattice_geometry<dim>(parameters), host, *labels);
        labels->state_variable_names = parameters.state_variable_names();
        if (cuda_ready.valid())
          cuda_ready.get();
        s.engine = make_engine<dim>(parameters.backend, lattice_grid<dim>(parameters), s.materials,
                                    parameters.shape_function);
        s.engine->set_sort_interval(parameters.sort_interval);
        s.engine->load(host, std::move(labels));
        s.engine_setup_seconds =
          std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      }
    else
      {
        s.timer.enter_subsection("setup: grid");
        s.grid = std::make_unique<BackgroundGrid<dim>>(parameters, s.communicator);
        s.timer.leave_subsection();
        s.timer.enter_subsection("setup: material points");
        count_points();
        s.points = std::make_unique<MaterialPoints<dim>>(*s.grid, parameters);
        s.points->insert(generation.get());
        s.timer.leave_subsection();
      }

    // MPI: points re-sorted into cells and ranks, grid repartitioned by work.
    // Pressure averaging in parallel: a point's cell at the end of a step must be an owned
    // or ghost cell of its rank (whose cell sums the exchange covers), i.e. less than one
    // cell outside its home cell. Re-sorting at half a cell (GIMP's safe distance already)
    // leaves a step's displacement of room; the check after each step asserts it.
    s.resort_at = std::min(parameters.resort_distance * safe_distance_outside_home_cell(parameters.shape_function),
                           s.parallel && parameters.pressure_averaging ? 0.5 : 1e300);
    if (s.parallel)
      {
        s.timer.enter_subsection("setup: engine");
        s.balance();
        if (cuda_ready.valid())
          cuda_ready.get();
        s.engine = make_engine<dim>(parameters.backend, *s.grid, s.materials, parameters.shape_function);
        s.engine->set_sort_interval(parameters.sort_interval);
        s.engine->load(*s.points);
        s.timer.leave_subsection();
      }

    s.print_header();
    s.apply_settings();

    if (parameters.equilibrate)
      s.equilibrate();

    s.next_output          = parameters.output_interval;
    s.last_progress        = std::chrono::steady_clock::now();
    s.last_checkpoint_wall = s.last_progress;
    s.set_up               = true;
    s.write_output();
    s.record_history();
    if (!grid_beside_first_steps)
      s.join_grid();
    s.stepping_start = std::chrono::steady_clock::now();
  }

  template <int dim>
  bool Simulator<dim>::finished() const
  {
    const State &s = *state;
    return s.stopped || !(s.time < s.parameters.end_time * (1 - 1e-12) &&
             (s.parameters.max_steps == 0 || s.step < long(s.parameters.max_steps)));
  }

  template <int dim>
  double Simulator<dim>::advance()
  {
    State            &s          = *state;
    const Parameters &parameters = s.parameters;
    AssertThrow(s.set_up, dealii::ExcMessage("Simulator::advance() needs setup() first."));
    if (s.grid_build.valid() && s.grid_build.wait_for(std::chrono::seconds(0)) == std::future_status::ready)
      s.join_grid();

    const double end = parameters.end_time;
    double       dt =
      parameters.adaptive_time_step ? parameters.cfl * s.h / (s.c_el + s.max_speed) : parameters.fixed_time_step;
    dt = std::min(dt, end - s.time);
    if (parameters.output_interval > 0)
      dt = std::min(dt, std::max(s.next_output - s.time, 1e-12 * end)); // land on output times
    s.dt = dt;

    const double ramp =
      parameters.gravity_ramp_time > 0 ? std::min(1.0, s.time / parameters.gravity_ramp_time) : 1.0;
    for (int d = 0; d < dim; ++d)
      s.settings.gravity[d] = ramp * parameters.gravity[d];

    s.switch_plasticity_on_when_due();
    s.engine_step(dt);
    s.work_of_gravity += dt * s.global_sum(s.gravity_power);
    s.time += dt;
    ++s.step;

    if (s.step % parameters.history_every == 0)
      s.record_history();
    if (parameters.output_interval > 0 && s.time >= s.next_output * (1 - 1e-12))
      {
        s.write_output();
        const double due = s.time * (1 + 1e-12);
        // An interval below the step (the step is at least 1e-12 End time) would take this loop
        // an interval at a time up to now: 1e296 turns for 1e-300 s, and for one below the
        // round-off of the time it never ends. Jump past now instead.
        if (s.next_output + parameters.output_interval <= due)
          s.next_output =
            std::max(due + parameters.output_interval, std::nextafter(due, std::numeric_limits<double>::infinity()));
        while (s.next_output <= due)
          s.next_output += parameters.output_interval;
      }

    // Checkpoints: every Step interval steps, and where a rank asks (wall clock, a stop).
    if (!s.parallel)
      s.request = s.local_request();
    if ((parameters.checkpoint_step_interval > 0 && s.step % parameters.checkpoint_step_interval == 0) ||
        s.request > 0)
      s.write_checkpoint();
    s.stopped = s.request == 2;

    const auto now = std::chrono::steady_clock::now();
    if (parameters.progress_interval > 0 &&
        std::chrono::duration<double>(now - s.last_progress).count() >= parameters.progress_interval)
      {
        const KeepPrecision keep(std::cout);
        const double        elapsed = std::chrono::duration<double>(now - s.wall_start).count();
        const double eta     = elapsed / (s.time - s.first_time) * (end - s.time);
        s.pcout << "  t = " << std::setw(10) << s.time << " s  step " << s.step << "  dt " << dt << "  "
                << std::setprecision(4) << (s.step - s.first_step) / elapsed << " steps/s  ETA " << eta << " s"
                << std::endl;
        s.last_progress = now;
      }
    return dt;
  }

  template <int dim>
  void Simulator<dim>::finish()
  {
    State            &s          = *state;
    const Parameters &parameters = s.parameters;
    AssertThrow(s.set_up, dealii::ExcMessage("Simulator::finish() needs setup() first."));
    if (s.finished_run)
      return;
    s.finished_run = true;
    s.join_grid(); // a short run may end before the grid thread does
    if (s.stopped)
      {
        stop_requested.store(false); // honoured: a later Simulator of this process runs on
        dealii::TimerOutput::Scope scope(s.timer, "output");
        s.output->finish();
        s.pcout << "dealii-mpm: stopped on request at t = " << s.time << " s after " << s.step
                << " steps; the run continues from the checkpoint " << s.last_checkpoint << " with --resume"
                << std::endl;
        return;
      }
    if (s.step % parameters.history_every != 0)
      s.record_history();
    const double end = parameters.end_time;
    if (!(parameters.output_interval > 0 &&
          std::abs(s.time - (s.next_output - parameters.output_interval)) < 1e-12 * end))
      s.write_output();
    // The handler is not brought up to date at the end: nothing reads it after the run
    // (the last output and the totals come from the engine). That hand-over cost 2.2 s of
    // the P2 run on the GPU (doc/performance.md). A checkpoint would have to do it.
    {
      dealii::TimerOutput::Scope scope(s.timer, "output");
      s.output->finish(); // the last files are complete
    }
    if (parameters.checkpoint_at_end && s.last_checkpoint_step != s.step)
      s.write_checkpoint();

    const KeepPrecision keep(std::cout);
    const double wall  = std::chrono::duration<double>(std::chrono::steady_clock::now() - s.wall_start).count();
    const double n_now = static_cast<double>(s.n_points_initial - s.n_removed);
    const long   steps = s.step - s.first_step; // by this process
    const double stepping =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - s.stepping_start).count();
    s.pcout << "dealii-mpm: done, t = " << s.time << " s after " << s.step << " steps in " << wall << " s wall ("
            << std::setprecision(3) << (n_now * steps) / wall << " point-updates/s); " << s.n_removed
            << " material point(s) left the grid and were removed.\n"
            << "  set-up " << wall - stepping << " s, then " << stepping << " s of steps and output ("
            << (n_now * steps) / stepping << " point-updates/s)\n"
            << "  loss checks: " << s.n_points_initial - s.n_removed << " points in the grid + " << s.n_removed
            << " removed = " << s.n_points_initial << " initial; mass in the grid + removed = initial mass to "
            << s.worst_mass_balance << " (largest relative difference over the history rows)\n";
    if (s.parallel)
      {
        s.pcout << "  MPI: " << s.n_resorts << " re-sorts of the points into cells and ranks, "
                << static_cast<long>(sum(double(s.points->n_sent), s.communicator)) << " points migrated, "
                << s.n_repartitions << " repartitions; work per rank max/mean " << s.imbalance() << "\n";
        // Ghost exchange per step: import + export of every ghost node's value, for each
        // array the scheme sums (MUSL: mass, momentum, force, then momentum again).
        const double ghosts = s.grid->partitioner->n_ghost_indices();
        const int    arrays = parameters.scheme == UpdateScheme::musl ? 3 * dim + 1 : 2 * dim + 1;
        const double bytes  = sum(double(s.grid->exchange_bytes_per_array()), s.communicator) * arrays;
        s.pcout << "  MPI: ghost nodes " << static_cast<long>(sum(ghosts, s.communicator)) << " in all, "
                << static_cast<long>(max(ghosts, s.communicator)) << " at most on one rank; exchange " << bytes
                << " bytes per step (" << arrays << " nodal arrays, each ghost value sent to its owner and back)\n";
      }
    s.pcout << "  output: " << s.output->n_outputs() << " outputs, " << s.output->task_seconds()
            << " s building and writing files on rank 0";
    if (parameters.output_in_background)
      s.pcout << " (background threads; the run waited " << s.output->waited_seconds() << " s for them)";
    s.pcout << "\n";
    s.pcout << "  results: " << s.output->directory() << "/particles.pvd, " << s.output->directory()
            << "/grid.pvd, " << s.output->directory() << "/history.csv" << std::endl;
  }

  template <int dim>
  void Simulator<dim>::run()
  {
    setup(true, nullptr);
    while (!finished())
      advance();
    finish();
  }

  template <int dim>
  std::string Simulator<dim>::write_checkpoint()
  {
    AssertThrow(state->set_up, dealii::ExcMessage("Simulator::write_checkpoint() needs setup() first."));
    return state->write_checkpoint();
  }

  template <int dim>
  bool Simulator<dim>::stopped() const
  {
    return state->stopped;
  }

  namespace
  {
    // A checkpoint resumes the run that wrote it: the same dimension, grid and materials.
    void check_resumable(const RunState &r, const Parameters &p, const std::string &folder)
    {
      const std::string of = "--resume: the checkpoint '" + folder + "' ";
      AssertThrow(r.dim == p.dim, dealii::ExcMessage(of + "is of a " + std::to_string(r.dim) +
                                                     "D run; the parameter file's Dimension is " +
                                                     std::to_string(p.dim) + "."));
      AssertThrow(r.lower == p.lower && r.upper == p.upper && r.cell_size == p.cell_size,
                  dealii::ExcMessage(of + "was written on another grid: Grid/Lower corner, Grid/Upper corner and "
                                          "Grid/Cell size must be those of the run that wrote it."));
      AssertThrow(r.n_materials == p.materials.size() && r.state_variable_names == p.state_variable_names(),
                  dealii::ExcMessage(of + "holds points of " + std::to_string(r.n_materials) +
                                     " material(s); Materials/Names declares " + std::to_string(p.materials.size()) +
                                     " (the materials, their order and their models must be those of the run that "
                                     "wrote it)."));
    }
  } // namespace

  template <int dim>
  void Simulator<dim>::resume(const std::string &path)
  {
    State            &s          = *state;
    const Parameters &parameters = s.parameters;
    AssertThrow(!s.set_up, dealii::ExcMessage("Simulator::resume() after setup(): call one of them."));
    const std::string folder = checkpoint::find(path);
    const RunState    r      = checkpoint::read_state(folder);
    check_resumable(r, parameters, folder);
    check_backend(parameters.backend);
    std::future<void> cuda_ready;
    if (parameters.backend == "cuda")
      cuda_ready = start_cuda_initialisation(s.communicator);

    s.h                 = parameters.cell_size;
    s.c_el              = r.elastic_wave_speed;
    s.m_min             = r.smallest_point_mass;
    s.time              = r.time;
    s.dt                = r.dt;
    s.max_speed         = r.max_speed;
    s.max_removed_speed = r.max_removed_speed;
    s.work_of_gravity   = r.work_of_gravity;
    s.balanced          = r.balanced;
    s.next_output       = r.next_output;
    s.step              = r.step;
    s.n_points_initial  = r.n_points_initial;
    s.n_removed         = r.n_removed;
    s.initial_mass      = r.initial_mass;
    s.n_resorts         = r.n_resorts;
    s.n_repartitions    = r.n_repartitions;
    s.equilibration     = r.equilibration;
    s.plastic           = r.plastic;
    s.materials         = parameters.materials;
    for (auto &m : s.materials)
      m.plasticity_enabled = s.plastic;

    s.output = std::make_unique<OutputWriter<dim>>(parameters, s.communicator, /*resuming=*/true);
    s.output->resume({r.n_outputs, r.grid_records, r.particle_records}, r.step);

    // The grid evenly partitioned; each rank reads every rank's points and keeps those in its
    // cells (one rank: all, including those that left the grid, as the engine held them).
    const unsigned int rank = dealii::Utilities::MPI::this_mpi_process(s.communicator);
    s.timer.enter_subsection("setup: grid");
    s.grid   = std::make_unique<BackgroundGrid<dim>>(parameters, s.communicator);
    s.points = std::make_unique<MaterialPoints<dim>>(*s.grid, parameters);
    const BackgroundGrid<dim> &grid = *s.grid;
    const PointSnapshot<dim>   saved =
      checkpoint::read_points<dim>(folder, r, [&](const HostPoints<dim, double> &p, const int i) {
        if (!s.parallel)
          return true;
        if (p.material[i] < 0) // left the grid (saved by one rank): dropped here, counted once
          {
            if (rank == 0)
              {
                ++s.n_dropped;
                s.dropped_mass += p.mass[i];
              }
            return false;
          }
        double x[dim];
        for (int d = 0; d < dim; ++d)
          x[d] = p.position[d][i];
        return p.material[i] >= 0 && grid.owned_cell(grid.lattice_cell_of(x)) != grid.triangulation.end();
      });
    AssertThrow(saved.points.n_state_variables() == static_cast<int>(parameters.state_variable_names().size()),
                dealii::ExcMessage("--resume: the points of '" + folder + "': " +
                                   state_variable_count_mismatch(saved.points.n_state_variables(),
                                                                 parameters.state_variable_names())));
    if (!s.parallel)
      s.points->replace(saved);
    s.points->n_sent = rank == 0 ? r.n_sent : 0;
    if (rank == 0) // the sums over ranks
      {
        s.n_dropped    += r.n_dropped;
        s.dropped_mass += r.dropped_mass;
      }
    s.timer.leave_subsection();

    s.resort_at = std::min(parameters.resort_distance * safe_distance_outside_home_cell(parameters.shape_function),
                           s.parallel && parameters.pressure_averaging ? 0.5 : 1e300);
    s.timer.enter_subsection("setup: engine");
    if (cuda_ready.valid())
      cuda_ready.get();
    s.start_from(saved);
    s.timer.leave_subsection();

    s.print_header();
    s.pcout << "  resumed from " << folder << " (written on " << r.n_ranks << " MPI rank(s)) at t = " << s.time
            << " s, step " << s.step << std::endl;
    s.apply_settings();
    s.last_progress = s.last_checkpoint_wall = std::chrono::steady_clock::now();
    s.last_checkpoint_step                   = s.step;
    s.last_checkpoint                        = folder;
    s.first_time                             = s.time;
    s.first_step                             = s.step;
    s.set_up                                 = true;
    s.stepping_start                         = s.last_progress;
  }

  template <int dim>
  double Simulator<dim>::time() const
  {
    return state->time;
  }

  template <int dim>
  long Simulator<dim>::step() const
  {
    return state->step;
  }

  template <int dim>
  const EquilibrationReport &Simulator<dim>::equilibration() const
  {
    return state->equilibration;
  }

  template <int dim>
  const Parameters &Simulator<dim>::parameters() const
  {
    return state->parameters;
  }

  template <int dim>
  HostPoints<dim, double> Simulator<dim>::points() const
  {
    AssertThrow(state->set_up, dealii::ExcMessage("Simulator::points() needs setup() first."));
    PointSnapshot<dim> snapshot;
    state->engine->snapshot(snapshot);
    return std::move(snapshot.points);
  }

  template <int dim>
  void Simulator<dim>::set_points(const HostPoints<dim, double> &new_points)
  {
    State &s = *state;
    AssertThrow(s.set_up, dealii::ExcMessage("Simulator::set_points() needs setup() first."));
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
      s.initial_mass = s.global_sum(t.mass + t.removed_mass + s.dropped_mass);
    };
    if (!s.parallel)
      {
        s.engine->load(new_points, snapshot.labels);
        return rebase_initial_mass();
      }
    for (int i = 0; i < new_points.size(); ++i)
      if (new_points.material[i] < 0)
        {
          ++s.n_dropped;
          s.dropped_mass += new_points.mass[i];
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
    s.engine->load(*s.points);
    ++s.n_resorts;
    if (s.balance())
      s.engine->load(*s.points);
    rebase_initial_mass();
  }

  void request_checkpoint_and_stop()
  {
    stop_requested.store(true);
  }

  namespace
  {
    template <int dim>
    bool run_from(const Parameters &parameters, MPI_Comm communicator, const std::string &resume_from)
    {
      Simulator<dim> simulator(parameters, communicator);
      if (!resume_from.empty())
        simulator.resume(resume_from);
      else if (parameters.initial_state_source == "FEM file")
        simulator.setup(load_fem_state_points<dim>(parameters, communicator));
      else
        {
          simulator.run();
          return !simulator.stopped();
        }
      while (!simulator.finished())
        simulator.advance();
      simulator.finish();
      return !simulator.stopped();
    }
  } // namespace

  bool run_simulation(const Parameters &parameters, MPI_Comm communicator, const std::string &resume_from)
  {
    if (parameters.dim == 2)
      return run_from<2>(parameters, communicator, resume_from);
    return run_from<3>(parameters, communicator, resume_from);
  }

  template class Simulator<2>;
  template class Simulator<3>;
} // namespace mpm
