#include "simulator_state.h"

#include <mpm/dealii/prm_reading.h>

namespace mpm
{
  template <int dim>
  Simulator<dim>::Simulator(const Parameters &parameters, MPI_Comm communicator)
    : state(std::make_unique<State>(parameters, communicator))
  {
    check_memory(parameters, communicator); // before anything large is allocated
    // A rank holds the nodes of its cells and one ring of ghost cells; a CPDI domain
    // stretched by the flow, and the cubic B-spline GIMP's stencil (two cells out of a
    // point's cell), reach beyond that ring, where their weights would be lost.
    const auto one_rank_only = [](auto member) { return runs_on_one_rank_only<decltype(member)>(); };
    const auto on_any_ranks  = [](auto member) { return !runs_on_one_rank_only<decltype(member)>(); };
    AssertThrow(!shape_is(parameters.shape_function, one_rank_only) ||
                  dealii::Utilities::MPI::n_mpi_processes(communicator) == 1,
                dealii::ExcMessage("Parameter 'Solver/Shape function': " + prm_reading::join_and(shape_names(false, one_rank_only)) +
                                   " run on one MPI rank (their stencils reach beyond the ghost cells of a rank's "
                                   "part of the grid); run this scene on one rank, or with " +
                                   prm_reading::join_or(shape_names(false, on_any_ranks)) + " on " +
                                   std::to_string(dealii::Utilities::MPI::n_mpi_processes(communicator)) +
                                   " ranks."));
  }

  template <int dim>
  Simulator<dim>::~Simulator() = default;

  namespace
  {
    // The elastic wave speed of the CFL condition: the largest over the points of sqrt(M / rho),
    // M the point's P-wave modulus (its own where Young's modulus is a random field) and rho
    // the body's density (the prm's bodies: from_prm, one per Material points/Body) or the
    // point's mass / volume (points handed over).
    template <int dim>
    double elastic_wave_speed(const std::vector<GeneratedBody<dim>> &bodies, const Parameters &p, const bool from_prm)
    {
      double c = 0;
      for (std::size_t b = 0; b < bodies.size(); ++b)
        {
          const HostPoints<dim, double> &points = bodies[b].points;
          for (int i = 0; i < points.size(); ++i)
            {
              const double M = point_p_wave_modulus(p.materials[points.material[i]], points.material_field[i]);
              c = std::max(c, std::sqrt(from_prm ? M / p.bodies[b].density : M * points.volume[i] / points.mass[i]));
            }
        }
      return c;
    }

    // Points handed over on several ranks come from each rank's own FEM cells. Every rank
    // needs all of them (it keeps those in its MPM cells, as with the prm's bodies, which
    // every rank generates whole), in one order on every rank: rank by rank.
    template <int dim>
    std::vector<GeneratedBody<dim>> gather_bodies(const std::vector<GeneratedBody<dim>> &local,
                                                  const PointFieldSet &fields, MPI_Comm comm)
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
            body.points.fields          = fields;
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
          {
            to.fields = body.points.fields;
            to.set_n_state_variables(body.points.n_state_variables());
          }
      to.resize(static_cast<int>(source.size()));
      for (std::size_t k = 0; k < source.size(); ++k)
        for_each_point_array<dim>(to, bodies[source[k].first].points,
                                  [&](auto &destination, const auto &origin) { destination[k] = origin[source[k].second]; });
      return one;
    }

    // Points given to setup() carry the state variables of the run's models (an empty body,
    // from a rank without FEM cells, may carry none).
    // Points handed over carry the run's fields (point_fields.h): those they lack start at
    // their initial value; a field the run does not carry is refused, by name.
    template <int dim>
    void carry_the_run_fields(std::vector<GeneratedBody<dim>> &bodies, const PointFieldSet &run)
    {
      for (GeneratedBody<dim> &body : bodies)
        for (int f = 0; f < n_point_fields; ++f)
          {
            const PointField field = static_cast<PointField>(f);
            AssertThrow(!body.points.fields.has(field) || run.has(field),
                        dealii::ExcMessage(std::string("Simulator::setup(bodies): the points handed over carry the "
                                                       "field '") + info(field).member +
                                           "', which this run does not (Parameters::point_fields)."));
            if (run.has(field) && !body.points.fields.has(field))
              body.points.carry(field);
          }
    }

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
    if (!parameters.method_choice_report.empty())
      s.pcout << parameters.method_choice_report << "\n";
    s.h    = parameters.cell_size;
    if (given_bodies != nullptr)
      {
        carry_the_run_fields(*given_bodies, parameters.point_fields);
        if (s.parallel)
          *given_bodies = gather_bodies(*given_bodies, parameters.point_fields, s.communicator);
        // APIC's affine matrices and CPDI2q's corners are the program's, not the caller's: points
        // handed over without them start with C = 0 and their initial rectangles.
        const int own = parameters.affine_state_variable() >= 0 ? parameters.affine_state_variable() :
                                                                    parameters.corner_state_variable();
        if (own >= 0)
          for (GeneratedBody<dim> &body : *given_bodies)
            if (body.points.size() > 0 && body.points.n_state_variables() == own)
              body.points.set_n_state_variables(static_cast<int>(parameters.state_variable_names().size()));
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
      }
    check_backend(parameters.backend.name); // before any set-up

    // Set-up. The CUDA context is created on a thread of its own (0.3-0.5 s on the GPU
    // host) and the bodies' points on another (they need the lattice only).
    std::future<void> cuda_ready;
    if (parameters.backend.name == "cuda")
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
    s.output = std::make_unique<OutputWriter<dim>>(parameters.output, parameters.backend.name == "cuda", s.communicator); // MPI: before the grid thread
    // Before plasticity start time every model behaves elastically.
    s.materials = parameters.materials;
    s.plastic   = !(parameters.plasticity_start_time > 0);
    for (auto &m : s.materials)
      m.plasticity_enabled = s.plastic;

    // Every rank generates every body, so these need no communication.
    auto count_points = [&]() {
      for (const GeneratedBody<dim> &body : generation.get())
        {
          s.losses.n_points_initial += body.points.size();
          for (const double m : body.points.mass)
            {
              s.losses.m_min = std::min(s.losses.m_min, m);
              s.losses.initial_mass += m;
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
      AssertThrow(s.losses.n_points_initial > 0,
                  dealii::ExcMessage("Parameter 'Material points': the bodies contain no material point (each "
                                     "body must cover at least one point site of the grid)."));
      s.c_el = elastic_wave_speed(generation.get(), parameters, given_bodies == nullptr);
      if (!parameters.adaptive_time_step)
        AssertThrow(parameters.fixed_time_step * s.c_el <= s.h,
                    dealii::ExcMessage("Parameter 'Solver/Fixed time step': " +
                                       dealii::Utilities::to_string(parameters.fixed_time_step) +
                                       " s exceeds the elastic stability limit h / c_el = " +
                                       dealii::Utilities::to_string(s.h / s.c_el) + " s (CFL > 1)."));
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
        if (s.builds_dealii_grid()) // not with Grid/Nodes = near material
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
          }
        const auto start = std::chrono::steady_clock::now();
        count_points();
        HostPoints<dim, double> host;
        auto                    labels = std::make_shared<PointLabels<dim>>();
        points_of_bodies(generation.get(), lattice_geometry<dim>(parameters), host, *labels);
        labels->state_variable_names = parameters.state_variable_names();
        if (cuda_ready.valid())
          cuda_ready.get();
        s.engine = make_engine<dim>(parameters.backend.name, lattice_grid<dim>(parameters, parameters.active_block_cells == 0), s.materials,
                                    parameters.shape_function, parameters.active_block_cells,
                                    parameters.backend.single_precision);
        s.engine->set_sort_interval(parameters.backend.sort_interval);
        s.engine->load(host, std::move(labels));
        s.engine_setup_seconds =
          std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      }
    else
      {
        s.timer.enter_subsection("setup: grid");
        // Partitioned by the bodies' points as it is built: no repartition moves them after.
        std::vector<const HostPoints<dim, double> *> start_points;
        for (const GeneratedBody<dim> &body : generation.get())
          start_points.push_back(&body.points);
        s.grid = std::make_unique<BackgroundGrid<dim>>(parameters, s.communicator, start_points);
        s.timer.leave_subsection();
        s.timer.enter_subsection("setup: material points");
        count_points();
        s.points = std::make_unique<MaterialPoints<dim>>(*s.grid, parameters);
        s.points->insert(generation.get());
        s.refine_near_material(); // (built fine around these points already)
        s.timer.leave_subsection();
      }

    if (s.parallel)
      {
        s.timer.enter_subsection("setup: engine");
        s.balance();
        if (cuda_ready.valid())
          cuda_ready.get();
        s.engine = make_engine<dim>(parameters.backend.name, *s.grid, s.materials, parameters.shape_function,
                                    parameters.backend.single_precision, parameters.active_block_cells);
        s.engine->set_sort_interval(parameters.backend.sort_interval);
        s.engine->load(*s.points);
        s.timer.leave_subsection();
      }
    s.set_resort_distance();

    s.print_header();
    s.apply_settings();

    if (parameters.initial_state.equilibrate)
      s.equilibrate();

    s.next_output          = parameters.output.interval;
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

    const double       end  = parameters.end_time;
    const TimeStepRule rule = s.time_step_rule(); // CFL, landing on the end and on output times

    const double ramp =
      parameters.gravity_ramp_time > 0 ? std::min(1.0, s.time / parameters.gravity_ramp_time) : 1.0;
    for (int d = 0; d < dim; ++d)
      s.settings.gravity[d] = ramp * parameters.gravity[d];

    s.switch_plasticity_on_when_due();
    double dt = 0;
    if (s.queue_steps())
      {
        // This step goes into the GPU's queue behind the last one, whose speed the device
        // uses for this step's time step; the host collects the last step meanwhile and
        // computes the same time step from the same speed.
        const bool speed_from_host = !s.step_in_queue;
        const auto start           = std::chrono::steady_clock::now();
        s.timed("MPM step", [&]() {
          s.engine->queue_step(s.settings, rule, s.time, s.next_output, speed_from_host, s.max_speed);
        });
        s.loop_times.engine += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        s.settle();
        dt                  = next_time_step(rule, s.max_speed, s.time, s.next_output);
        s.step_in_queue     = true;
        s.queued_dt         = dt;
        s.queued_time_after = s.time + dt;
        s.queued_step_after = s.step + 1;
      }
    else
      {
        dt = next_time_step(rule, s.max_speed, s.time, s.next_output);
        s.engine_step(dt);
        s.work_of_gravity += dt * s.global_sum(s.gravity_power);
      }
    s.dt = dt;
    s.time += dt;
    ++s.step;

    if (s.step % parameters.output.history_every == 0)
      s.record_history();
    if (parameters.output.interval > 0 && s.time >= s.next_output * (1 - 1e-12))
      {
        s.write_output();
        const double due = s.time * (1 + 1e-12);
        // An interval below the step (the step is at least 1e-12 End time) would take this loop
        // an interval at a time up to now: 1e296 turns for 1e-300 s, and for one below the
        // round-off of the time it never ends. Jump past now instead.
        if (s.next_output + parameters.output.interval <= due)
          s.next_output =
            std::max(due + parameters.output.interval, std::nextafter(due, std::numeric_limits<double>::infinity()));
        while (s.next_output <= due)
          s.next_output += parameters.output.interval;
      }

    // Checkpoints: every Step interval steps, and where a rank asks (wall clock, a stop).
    if (!s.parallel)
      s.request = s.local_request();
    if ((parameters.checkpoint.step_interval > 0 && s.step % parameters.checkpoint.step_interval == 0) ||
        s.request > 0)
      s.write_checkpoint();
    s.stopped = s.request == 2;

    const auto now = std::chrono::steady_clock::now();
    if (parameters.output.progress_interval > 0 &&
        std::chrono::duration<double>(now - s.last_progress).count() >= parameters.output.progress_interval)
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
    s.settle();    // the last queued step
    s.join_grid(); // a short run may end before the grid thread does
    if (s.stopped)
      {
        stop_requested.store(false); // honoured: a later Simulator of this process runs on
        dealii::TimerOutput::Scope scope(s.timer, "output: waiting for the last files");
        s.output->finish();
        s.pcout << "dealii-mpm: stopped on request at t = " << s.time << " s after " << s.step
                << " steps; the run continues from the checkpoint " << s.last_checkpoint << " with --resume"
                << std::endl;
        return;
      }
    if (s.step % parameters.output.history_every != 0)
      s.record_history();
    const double end = parameters.end_time;
    // Not again where the last output was at this time (End time = 0 included: one output at t = 0).
    if (!(parameters.output.interval > 0 && std::abs(s.time - (s.next_output - parameters.output.interval)) <=
                                              1e-12 * std::max(end, parameters.output.interval)))
      s.write_output();
    // The handler is not brought up to date at the end: nothing reads it after the run
    // (the last output and the totals come from the engine). That hand-over cost 2.2 s of
    // the P2 run on the GPU (doc/performance.md). A checkpoint would have to do it.
    {
      // A row of its own: the "output" row then counts one call per output, as the summary does.
      dealii::TimerOutput::Scope scope(s.timer, "output: waiting for the last files");
      s.output->finish(); // the last files are complete
    }
    if (parameters.checkpoint.at_end && s.last_checkpoint_step != s.step)
      s.write_checkpoint();

    const KeepPrecision keep(std::cout);
    const double wall  = std::chrono::duration<double>(std::chrono::steady_clock::now() - s.wall_start).count();
    const double n_now = static_cast<double>(s.losses.n_points_initial - s.n_removed);
    const long   steps = s.step - s.first_step; // by this process
    const double stepping =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - s.stepping_start).count();
    s.pcout << "dealii-mpm: done, t = " << s.time << " s after " << s.step << " steps in " << wall << " s wall ("
            << std::setprecision(3) << (n_now * steps) / wall << " point-updates/s); " << s.n_removed
            << " material point(s) left the grid and were removed.\n"
            << "  set-up " << wall - stepping << " s, then " << stepping << " s of steps and output ("
            << (n_now * steps) / stepping << " point-updates/s)\n"
            << "  loss checks: " << s.losses.n_points_initial - s.n_removed << " points in the grid + " << s.n_removed
            << " removed = " << s.losses.n_points_initial << " initial; mass in the grid + removed = initial mass to "
            << s.losses.worst_mass_balance << " (largest relative difference over the history rows)\n";
    if (s.engine->follows_material() && s.parallel)
      s.pcout << "  nodes near the material: " << s.engine->n_active_nodes() << " at the end, "
              << s.engine->most_nodes() << " at most (summed over the ranks); chosen again "
              << std::max(0L, s.engine->node_choices() - 1) << " times (at every re-sort and repartition)\n";
    else if (s.engine->follows_material())
      s.pcout << "  nodes near the material: " << s.engine->n_active_nodes() << " at the end, "
              << s.engine->most_nodes() << " at most; chosen again " << s.migration.n_node_refreshes
              << " times; the points' distances from the cells they were in checked in " << s.migration.n_home_checks
              << " of " << steps << " steps\n";
    if (s.parallel && s.grid->coarse_away_from_material())
      s.pcout << "  deal.II's grid: fine only near the material, " << s.grid->triangulation.n_global_active_cells()
              << " cells at the end; refined " << s.grid->n_refinements << " times as the material spread\n";
    if (s.engine->follows_material() && !s.parallel)
      s.pcout << "  nodes near the material: numbered as the box around the material (no lookup) in "
              << s.engine->node_choices_as_box() << " of " << s.engine->node_choices()
              << " choices (the others through the block table)\n";
    if (s.parallel)
      {
        s.pcout << "  MPI: " << s.migration.n_resorts << " re-sorts of the points into cells and ranks, "
                << static_cast<long>(sum(double(s.points->n_sent), s.communicator)) << " points migrated, "
                << s.migration.n_repartitions << " repartitions; work per rank max/mean " << s.imbalance() << "\n"
                << "  MPI: the points' distances from their home cells checked in " << s.migration.n_home_checks << " of "
                << steps << " steps (in the others a bound from the largest speed showed no point could be more than "
                << s.migration.resort_at << " cells out)\n";
        // Ghost exchange per step: import + export of every ghost node's value, for each
        // array the scheme sums (MUSL: mass, momentum, force, then momentum again).
        const double ghosts = s.grid->partitioner->n_ghost_indices();
        const int    arrays = parameters.scheme == UpdateScheme::musl ? 3 * dim + 1 : 2 * dim + 1;
        const double bytes  = sum(double(s.grid->exchange_bytes_per_array(parameters.backend.single_precision ? sizeof(float) :
                                                                                                  sizeof(double))),
                                 s.communicator) *
                             arrays;
        s.pcout << "  MPI: ghost nodes " << static_cast<long>(sum(ghosts, s.communicator)) << " in all, "
                << static_cast<long>(max(ghosts, s.communicator)) << " at most on one rank; exchange " << bytes
                << " bytes per step (" << arrays << " nodal arrays, each ghost value sent to its owner and back)\n";
        const double exchange = max(s.engine->exchange_seconds(), s.communicator);
        const double host_part = max(s.engine->exchange_host_seconds(), s.communicator);
        if (exchange >= 0 && steps > 0)
          s.pcout << "  GPU ghost exchange: " << exchange << " s on the slowest rank, " << 1e3 * exchange / steps
                  << " ms per step (device time from the end of the work before each exchange to the sums in place: "
                     "the copies, the host's part and MPI; where it overlaps, other points' passes run meanwhile), "
                     "of which the host's part "
                  << 1e3 * host_part / steps << " ms per step (copies into the partitioner's layout and MPI)\n";
        const double first_share = max(s.engine->share_of_points_before_overlap(), s.communicator);
        if (exchange >= 0 && steps > 0 && first_share >= 0)
          s.pcout << "  GPU exchange overlap: the passes of at most " << 100 * first_share
                  << "% of a rank's points (mean over the sorts) run before each exchange, the others' while it "
                     "travels\n";
      }
    if (steps > 0)
      {
        // Per rank: where the loop's wall time went, ms per step (the rest of a step's wall
        // time is the history, output and bookkeeping of advance()).
        const auto             &l     = s.loop_times;
        const double            per   = 1e3 / std::max(1L, l.steps);
        const std::vector<double> mine = {per * l.engine, per * l.timer_sync, per * l.home_check,
                                          per * l.reduction, 1e3 * l.resorts};
        const auto all = s.parallel ? dealii::Utilities::MPI::gather(s.communicator, mine) :
                                      std::vector<std::vector<double>>{mine};
        for (std::size_t rank = 0; rank < all.size(); ++rank)
          s.pcout << "  loop on rank " << rank << ", ms per step: engine step " << all[rank][0]
                  << ", timer synchronisation " << all[rank][1] << ", home-cell check " << all[rank][2]
                  << ", reduction over ranks " << all[rank][3] << "; re-sorts and repartitions "
                  << all[rank][4] << " ms in all\n";
      }
    s.pcout << "  output: " << s.output->n_outputs() << " outputs, " << s.output->task_seconds()
            << " s building and writing files on rank 0";
    if (parameters.output.in_background)
      s.pcout << " (background threads; the run waited " << s.output->waited_seconds() << " s for them)";
    s.pcout << "\n";
    // Only the files this run wrote (Output/Write particles, Write grid fields, Write particle table).
    const std::string where   = s.output->directory() + "/";
    const bool        outputs = s.output->n_outputs() > 0;
    s.pcout << "  results: ";
    if (outputs && parameters.output.write_particles)
      s.pcout << where << "particles.pvd, ";
    if (outputs && parameters.output.write_grid_fields)
      s.pcout << where << "grid.pvd, ";
    if (outputs && parameters.output.write_particle_table)
      s.pcout << where << "particle_table_NNNNN.R.csv (one per output and rank), ";
    s.pcout << where << "history.csv" << std::endl;
    // Files an earlier run left here would be found by a glob or a file dialog beside this
    // run's: said once, not removed (they are the user's).
    const auto earlier = s.output->files_of_earlier_runs();
    if (!earlier.empty())
      warn_about_parameter("Output/Directory",
                           "'" + s.output->directory() + "' also holds " + std::to_string(earlier.size()) +
                             " file(s) that this run did not write, left by an earlier run (" + earlier.front() +
                             (earlier.size() > 1 ? " ... " + earlier.back() : std::string()) +
                             "); they are in none of this run's .pvd records. Remove them, or give each run its "
                             "own directory.");
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

  namespace
  {
    template <int dim>
    bool run_from(const Parameters &parameters, MPI_Comm communicator, const std::string &resume_from)
    {
      Simulator<dim> simulator(parameters, communicator);
      if (!resume_from.empty())
        simulator.resume(resume_from);
      else if (parameters.initial_state.source == "FEM file")
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
