// The state of a Simulator between its steps, and what its source files share
// (source/dealii/simulator*.cc, instability_message.cc). Private to the library.
#ifndef MPM_SOURCE_SIMULATOR_STATE_H
#define MPM_SOURCE_SIMULATOR_STATE_H

#include <mpm/core/migration.h>
#include <mpm/core/time_step_rule.h>
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
#include <cstdlib>
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

  namespace simulator_internal
  {
    // Set by request_checkpoint_and_stop (a signal handler): lock-free, so async-signal-safe.
    inline std::atomic<bool> stop_requested{false};
    static_assert(std::atomic<bool>::is_always_lock_free);

    template <int dim>
    inline PointTotals<dim, double> global_totals(PointTotals<dim, double> t, MPI_Comm comm)
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
    inline StepReduction<double> nan_as_infinite(StepReduction<double> r)
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
    std::string describe_instability(Engine<dim> &engine, const Parameters &p, double c_el, double dt,
                                     double reported_speed, bool equilibrating, bool parallel,
                                     MPI_Comm communicator);
  } // namespace simulator_internal

  using namespace simulator_internal;

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

    // The loss checks (check_losses): the points and the mass the run started with, the
    // smallest point mass, and on this rank the points dropped from the engine after leaving
    // the grid (re-sorts), their number and mass; the largest relative mass balance seen.
    struct Losses
    {
      long   n_points_initial = 0;
      double m_min            = 1e300;
      double initial_mass = 0, dropped_mass = 0, worst_mass_balance = 0;
      long   n_dropped    = 0;
    } losses;
    // One rank: deal.II's grid and handler being built on a thread (see setup()).
    std::future<GridAndPoints> grid_build;
    const std::string          beside_grid          = "setup and first steps, beside deal.II's grid";
    double                     engine_setup_seconds = 0;
    bool                       initial_output_pending = false;

    // Where the points are among the cells and ranks (simulator_migration.cc).
    struct Migration
    {
      double resort_at = 1e300; // re-sort (or choose the nodes again) once a point is farther out than this
      // Several ranks: the ghost layer's width in cells (one deal.II cell). The re-sort finds a
      // point's new cell only among its rank's owned and ghost cells, so the points are re-sorted
      // before one could end the next step beyond it (next_step: this step's displacement, the
      // estimate of the next one's), whatever resort_at allows.
      double ghost_width = 1e300;
      double next_step   = 0;
      // Several ranks: a bound on the distance of any point outside its home cell (cells): the
      // largest distance at the last check (0 after a re-sort) plus step_displacement_bound of
      // every step since; the points are checked only once it exceeds resort_at (n_home_checks
      // counts those checks). Unknown until the first check: a resumed run's points may sit
      // outside the cells they were saved in.
      double drift_bound   = std::numeric_limits<double>::infinity();
      long   n_home_checks = 0;
      // MPM_VERIFY_DRIFT_BOUND=1 (tests): check the points every step and stop where one is
      // farther out than the bound says.
      const bool verify_drift_bound = std::getenv("MPM_VERIFY_DRIFT_BOUND") != nullptr;
      long       n_resorts = 0, n_repartitions = 0;
      long       n_node_refreshes = 0; // one rank, nodes near the material: how often they were chosen again
      double     balanced         = 1; // imbalance right after the last repartition: what p4est achieves
    } migration;

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
      return parameters.checkpoint.wall_interval > 0 && minutes >= parameters.checkpoint.wall_interval ? 1 : 0;
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
    double imbalance() const;

    // Repartition when the work per rank is out of balance by more than the threshold and
    // by clearly more than the last repartition could reach (no futile repeats when the
    // granularity of cells forbids better). Points per rank only change at re-sorts, so
    // this is checked at the start and after each re-sort.
    bool balance();

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

    // Where a rank's wall time of the stepping loop goes, per part (seconds, summed over
    // the steps): the engine's step, TimerOutput's synchronisation around it (a barrier and
    // two reductions per step on several ranks, the wait for the slowest rank included),
    // the check of how far points are from their home cells, the reduction over the ranks
    // after the step, the re-sorts and repartitions. Printed per rank at the end.
    struct LoopTimes
    {
      double engine = 0, timer_sync = 0, home_check = 0, reduction = 0, resorts = 0;
      long   steps  = 0;
    };
    LoopTimes loop_times;

    // One step of the engine with the current settings, and what every step needs after it:
    // the largest speeds over the ranks, the MPI re-sort when points have strayed, the
    // stability check. Time and step counters are the caller's.
    void engine_step(const double dt)
    {
      using clock            = std::chrono::steady_clock;
      const auto   entered   = clock::now();
      double       in_engine = 0;
      const StepReduction<double> r = nan_as_infinite(timed("MPM step", [&]() {
        const auto                  start = clock::now();
        const StepReduction<double> step  = engine->step(settings, dt);
        in_engine = std::chrono::duration<double>(clock::now() - start).count();
        return step;
      }));
      const auto stepped = clock::now();
      loop_times.engine += in_engine;
      loop_times.timer_sync += std::chrono::duration<double>(stepped - entered).count() - in_engine;
      ++loop_times.steps;
      after_step(r, dt, time + dt, step + 1, stepped);
    }

    // Backend/Queue steps (one rank on the GPU, nodes everywhere): each step is queued on the
    // device before the last one has ended, and its reductions are collected one step later
    // (settle()), so that the GPU never waits for the host between steps.
    bool queue_steps() const
    {
      return parameters.backend.queue_steps && !parallel && !equilibrating && engine->queues_steps() &&
             !engine->follows_material();
    }
    // The step queued last and not yet collected: the time step the host's rule gave it, the
    // time and step count after it.
    bool   step_in_queue = false;
    double queued_dt = 0, queued_time_after = 0;
    long   queued_step_after = 0;

    // The rule of the next time step (the host's and, for queued steps, the device's).
    TimeStepRule time_step_rule() const
    {
      TimeStepRule rule;
      rule.adaptive         = parameters.adaptive_time_step;
      rule.cfl_times_h      = parameters.cfl * h;
      rule.wave_speed       = c_el;
      rule.fixed_step       = parameters.fixed_time_step;
      rule.end_time         = parameters.end_time;
      rule.lands_on_outputs = parameters.output.interval > 0;
      rule.shortest_landing = 1e-12 * parameters.end_time;
      return rule;
    }

    // Collects the queued step: its reductions, the checks after it and the work of gravity,
    // as engine_step and the loop do for a step that was not queued. Before anything reads
    // or changes the points, the time history or the totals.
    void settle()
    {
      if (!step_in_queue)
        return;
      step_in_queue      = false;
      const auto       start = std::chrono::steady_clock::now();
      const QueuedStep q     = timed("MPM step", [&]() { return engine->collect_step(); });
      // The engine's time of a queued step: its queueing (advance()) and the wait for its end.
      loop_times.engine += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      ++loop_times.steps;
      AssertThrow(q.dt == queued_dt,
                  dealii::ExcMessage("Internal: the GPU took a time step of " + dealii::Utilities::to_string(q.dt) +
                                     " s where the host's rule gives " + dealii::Utilities::to_string(queued_dt) +
                                     " s (Backend/Queue steps = false avoids the queue)."));
      after_step(nan_as_infinite(q.reduction), q.dt, queued_time_after, queued_step_after,
                 std::chrono::steady_clock::now());
      work_of_gravity += q.dt * gravity_power;
    }

    // What every step needs after it (engine_step's list), from its reductions r; dt, and the
    // time and step count after it, for the messages.
    void after_step(const StepReduction<double> &r, const double dt, const double time_after, const long step_after,
                    const std::chrono::steady_clock::time_point stepped)
    {
      using clock       = std::chrono::steady_clock;
      gravity_power     = r.gravity_power;
      max_speed         = r.max_speed;
      max_removed_speed = r.max_removed_speed;
      // Where a message says the step was; built only for a message (a string per step costs).
      const auto when = [&]() {
        return equilibrating ?
                 "in damped step " + std::to_string(equilibration.steps + 1) + " of the equilibration" :
                 "at t = " + dealii::Utilities::to_string(time_after) + " s (step " + std::to_string(step_after) +
                   ")";
      };
      if (parallel)
        {
          // One reduction for the next time step: the largest speeds, and what the ranks ask
          // for after the step (a checkpoint, a stop).
          double local[3] = {r.max_speed, r.max_removed_speed, double(local_request())}, global[3];
          dealii::Utilities::MPI::max(dealii::ArrayView<const double>(local, 3), communicator,
                                      dealii::ArrayView<double>(global, 3));
          const auto reduced = clock::now();
          loop_times.reduction += std::chrono::duration<double>(reduced - stepped).count();
          max_speed         = global[0];
          max_removed_speed = global[1];
          request           = static_cast<int>(global[2]);
          const double distance = distance_outside_home_cells(dt, when);
          const auto checked = clock::now();
          loop_times.home_check += std::chrono::duration<double>(checked - reduced).count();
          AssertThrow(!parameters.pressure_averaging || distance < 1,
                      dealii::ExcMessage("Parameter 'Solver/Pressure averaging': " + when() + " a point moved to " +
                                         dealii::Utilities::to_string(distance) +
                                         " cells outside the cell it was sorted into, beyond the ghost cells "
                                         "whose pressure sums are exchanged between ranks. Reduce 'Solver/CFL "
                                         "number' or the time step."));
          if (resort_needed(distance))
            {
              bool refined;
              {
                dealii::TimerOutput::Scope scope(timer, "migrate points");
                resort();
                refined = refine_near_material();
              }
              if (balance() || refined)
                engine->load(*points);
              loop_times.resorts += std::chrono::duration<double>(clock::now() - checked).count();
            }
        }
      else if (engine->follows_material())
        {
          // The nodes near the material chosen again before a point's stencil can leave them.
          const double distance = distance_outside_home_cells(dt, when);
          const auto   checked  = clock::now();
          loop_times.home_check += std::chrono::duration<double>(checked - stepped).count();
          AssertThrow(!parameters.pressure_averaging || distance < parameters.active_block_cells,
                      dealii::ExcMessage("Parameter 'Solver/Pressure averaging': " + when() + " a point moved " +
                                         dealii::Utilities::to_string(distance) +
                                         " cells out of the cell it was in when the nodes near the material were "
                                         "chosen, beyond the kept cells whose pressure sums the step used (Grid/"
                                         "Active block size = " + std::to_string(parameters.active_block_cells) +
                                         "). Reduce 'Solver/CFL number' or the time step, or enlarge the blocks."));
          if (resort_needed(distance))
            {
              engine->refresh_active_nodes();
              ++migration.n_node_refreshes;
              migration.drift_bound = 0; // every point is in its home cell now
              loop_times.resorts += std::chrono::duration<double>(clock::now() - checked).count();
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
    void equilibrate();

    // The step's settings from the prm (gravity is set by each step, from the ramp).
    void apply_settings()
    {
      settings.scheme             = parameters.scheme;
      settings.damping            = parameters.damping;
      settings.damping_form       = parameters.damping_form;
      settings.damping_threshold  = parameters.damping_threshold;
      settings.flip_fraction      = parameters.flip_fraction;
      settings.flip_fixed_velocity_change = parameters.flip_fixed_velocity_change;
      settings.affine_state_variable = parameters.affine_state_variable();
      settings.affine_matrix         = parameters.affine_matrix;
      settings.corner_state_variable = parameters.corner_state_variable();
      settings.domain_update      = parameters.domain_update;
      settings.pressure_averaging = parameters.pressure_averaging;
      settings.disconnected_points =
        std::any_of(parameters.materials.begin(), parameters.materials.end(),
                    [](const MaterialParameters<double> &m) { return m.disconnection_volume_ratio > 0; });
      settings.mass_tolerance     = 1e-12 * losses.m_min; // nodes lighter than that carry no velocity
      settings.wall_faces         = 0;
      for (unsigned int id = 0; id < 2 * dim; ++id)
        if (parameters.boundary[id] != BoundaryType::free)
          settings.wall_faces |= std::uint8_t(1u << id);
    }

    void print_header();

    // Everything of the run but its points and grid, for a checkpoint (collective: the
    // points handed between ranks are summed).
    RunState run_state() const;

    // Several ranks near the material: deal.II's grid refined where the points are about to
    // need it (MaterialPoints::refine_near_points); whether it was (collective).
    bool refine_near_material();

    // Several ranks: the partition of the grid by the points' work as it is now (where the
    // run repartitions at all). A pure function of the points' cells, whichever partition the
    // grid had before: a run resumed on an even partition comes to the same one.
    void partition_by_current_work();

    // A checkpoint of the run after the current step. Then the engine starts anew from the
    // saved points exactly as a run resumed from the checkpoint does (on several ranks: the
    // handler filled with them, the grid partitioned by their work, the engine loaded from
    // the handler; on one: the engine loaded with them, forgetting what it built for the
    // points before, the CPU's scatter slabs): the resumed run is bit-identical to this one.
    std::string write_checkpoint();

    // The engine (made where there is none yet) starts from `saved`: a checkpoint's points,
    // all of this rank's (one rank) or those in its cells (several).
    void start_from(const PointSnapshot<dim> &saved);

    // Whether a point this far out of its home cell is to be re-sorted (or the nodes chosen again).
    bool resort_needed(const double distance) const
    {
      return distance > migration.resort_at || distance + migration.next_step >= migration.ghost_width;
    }

    // The MPI re-sort, counting the points it drops (those that left the grid): they must be
    // the ones the engine held as removed.
    void resort();

    // How far a point can be outside the cell it was sorted into (several ranks) or was in
    // when the engine chose its nodes (one rank, nodes near the material): the largest
    // distance at the last check plus the steps' bounds since, while that stays below the
    // re-sort distance (the distance is 1-Lipschitz in the position, max-norm); the points'
    // largest distance (a pass over the points and, on several ranks, a reduction) once it
    // does. The re-sorts come at the same steps either way.
    template <typename When>
    double distance_outside_home_cells(const double dt, const When &when)
    {
      migration.drift_bound += step_displacement_bound(dt);
      migration.next_step = dt * std::max(max_speed, max_removed_speed) / h;
      double     distance = migration.drift_bound;
      const bool needed   = !(migration.drift_bound <= migration.resort_at) ||
                          migration.drift_bound + migration.next_step >= migration.ghost_width;
      if (needed || migration.verify_drift_bound)
        {
          distance = global_max(engine->max_distance_outside_home_cells());
          migration.n_home_checks += needed;
          AssertThrow(needed || distance <= migration.drift_bound,
                      dealii::ExcMessage("Internal error (MPM_VERIFY_DRIFT_BOUND): a point is " +
                                         dealii::Utilities::to_string(distance) +
                                         " cells outside its home cell, beyond the bound " +
                                         dealii::Utilities::to_string(migration.drift_bound) + " " + when()));
          if (needed)
            migration.drift_bound = distance;
        }
      return distance;
    }

    // Whether the run builds deal.II's grid and ParticleHandler of the whole box: not on one
    // rank with Grid/Nodes = near material, whose engine keeps only the nodes near the
    // points and writes the grid files from them (cost and memory follow the material).
    bool builds_dealii_grid() const { return parallel || parameters.active_block_cells == 0; }

    // Cells a point may move out of its home cell before the run re-sorts the points (several
    // ranks) or the engine chooses the nodes near the material again (one rank): set once the
    // engine exists. Pressure averaging on several ranks: a point's cell at the end of a step
    // must be an owned or ghost cell of its rank (whose cell sums the exchange covers), i.e.
    // less than one cell outside its home cell. Re-sorting at half a cell (GIMP's safe
    // distance already) leaves a step's displacement of room; the check after each step
    // asserts it.
    void set_resort_distance();

    // A bound on how far (in cells, max-norm) any point moved in the step of length dt just
    // taken, from the largest speeds over the ranks; infinite where none is known. MUSL moves
    // the points with the nodal velocities of its remap, m_i v_i = sum_p N_ip m_p v_p: a
    // mass-weighted mean of the points' new velocities (those that left the grid in the step
    // included), so no component exceeds the largest point speed; the shape functions'
    // weights are non-negative and sum to at most 1, so a point moves at most dt times that.
    // Wall contact and fixed components only shrink nodal velocities. APIC's remap adds
    // C_p (x_i - x_p) and USL/USF move the points with v_i + dt a_i: no such bound.
    double step_displacement_bound(const double dt) const;

    // Points are never made or lost but by leaving the grid: the points in the grid and those
    // removed make the initial number exactly, and their masses the initial mass to round-off
    // (Engine::relative_mass_round_off: 1e-9 in double, the sums' order differs; 1e-7 in float,
    // each mass rounded once). Throws where either fails: a bug, not a bad input.
    // Returns (removed mass, relative mass balance).
    std::pair<double, double> check_losses(const PointTotals<dim, double> &totals);

    void record_history();

    // Output reads a snapshot of the engine's points: no hand-over to the handler, which
    // is brought up to date only where it is needed (re-sorts, repartitions).
    void write_output();
  };
} // namespace mpm

#endif
