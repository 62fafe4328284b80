#include <mpm/core/migration.h>
#include <mpm/dealii/background_grid.h>
#include <mpm/dealii/cuda_engine.h>
#include <mpm/dealii/engine.h>
#include <mpm/dealii/material_points.h>
#include <mpm/dealii/output_writer.h>
#include <mpm/dealii/simulator.h>

#include <deal.II/base/conditional_ostream.h>
#include <deal.II/base/mpi.h>
#include <deal.II/base/timer.h>

#include <chrono>
#include <cmath>
#include <future>
#include <iomanip>
#include <iostream>

namespace mpm
{
  using dealii::Utilities::MPI::max;
  using dealii::Utilities::MPI::min;
  using dealii::Utilities::MPI::sum;

  template <int dim>
  Simulator<dim>::Simulator(const Parameters &parameters, MPI_Comm communicator)
    : parameters(parameters)
    , communicator(communicator)
  {}

  namespace
  {
    template <int dim>
    PointTotals<dim, double> global_totals(PointTotals<dim, double> t, MPI_Comm comm)
    {
      t.mass           = sum(t.mass, comm);
      t.kinetic_energy = sum(t.kinetic_energy, comm);
      t.n_points       = sum(t.n_points, comm);
      for (int d = 0; d < dim; ++d)
        {
          t.momentum[d] = sum(t.momentum[d], comm);
          t.lower[d]    = min(t.lower[d], comm);
          t.upper[d]    = max(t.upper[d], comm);
        }
      return t;
    }

    // Largest elastic wave speed over the bodies, sqrt((K + 4G/3) / rho).
    double elastic_wave_speed(const Parameters &p)
    {
      double c = 0;
      for (unsigned int b = 0; b < p.bodies.size(); ++b)
        c = std::max(c, std::sqrt(p.materials[p.body_material[b]].elastic.p_wave_modulus() / p.bodies[b].density));
      return c;
    }
  } // namespace

  template <int dim>
  void Simulator<dim>::run()
  {
    const double c_el = elastic_wave_speed(parameters);
    const double h    = parameters.cell_size;
    if (!parameters.adaptive_time_step)
      AssertThrow(parameters.fixed_time_step * c_el <= h,
                  dealii::ExcMessage("Parameter 'Solver/Fixed time step': " +
                                     dealii::Utilities::to_string(parameters.fixed_time_step) +
                                     " s exceeds the elastic stability limit h / c_el = " +
                                     dealii::Utilities::to_string(h / c_el) + " s (CFL > 1)."));

    const unsigned int n_ranks  = dealii::Utilities::MPI::n_mpi_processes(communicator);
    const bool         parallel = n_ranks > 1;
    check_backend(parameters.backend, n_ranks); // before any set-up

    dealii::ConditionalOStream pcout(std::cout, dealii::Utilities::MPI::this_mpi_process(communicator) == 0);
    dealii::TimerOutput timer(communicator, pcout, dealii::TimerOutput::summary, dealii::TimerOutput::wall_times);
    const auto wall_start = std::chrono::steady_clock::now();
    auto       seconds_since = [](const std::chrono::steady_clock::time_point t) {
      return std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
    };

    // Set-up. The CUDA context is created on a thread of its own (0.3-0.5 s on the GPU
    // host) and the bodies' points on another (they need the lattice only).
    std::future<void> cuda_ready;
    if (parameters.backend == "cuda")
      cuda_ready = start_cuda_initialisation();
    std::shared_future<std::vector<GeneratedBody<dim>>> generation =
      std::async(std::launch::async, [this]() { return generate_bodies<dim>(parameters); }).share();
    // Declared before the output, whose background tasks read the grid: destroyed after it.
    std::unique_ptr<BackgroundGrid<dim>> grid;
    std::unique_ptr<MaterialPoints<dim>> points;
    std::unique_ptr<Engine<dim>>         engine;
    OutputWriter<dim> output(parameters, communicator); // MPI (a broadcast): before the grid thread starts
    // Before plasticity start time every model behaves elastically.
    std::vector<MaterialParameters<double>> materials = parameters.materials;
    bool plastic = !(parameters.plasticity_start_time > 0);
    for (auto &m : materials)
      m.plasticity_enabled = plastic;

    // Every rank generates every body, so these need no communication.
    long   n_points_initial = 0;
    double m_min            = 1e300;
    auto   count_points     = [&]() {
      for (const GeneratedBody<dim> &body : generation.get())
        {
          n_points_initial += body.points.size();
          for (const double m : body.points.mass)
            m_min = std::min(m_min, m);
        }
      AssertThrow(n_points_initial > 0,
                  dealii::ExcMessage("Parameter 'Material points': the bodies contain no material point (each "
                                     "body must cover at least one point site of the grid)."));
    };

    // One rank: the engine keeps its own nodes on the lattice and starts from the bodies,
    // so the steps start while deal.II builds the grid and fills the ParticleHandler on a
    // thread (0.6-1.4 s of the 3D collapse's set-up on the GPU host). deal.II initialises
    // MPI for serialized calls only, and that thread calls MPI (the Partitioner, the
    // handler's counts); until it is joined this thread calls none: no reduction over one
    // rank, no TimerOutput section (its timers call MPI_Comm_size) except the one entered
    // before the thread starts and left after it is joined, and no output (which needs the
    // grid: the t = 0 output is written once it exists, a later one waits for it).
    struct GridAndPoints
    {
      std::unique_ptr<BackgroundGrid<dim>> grid;
      std::unique_ptr<MaterialPoints<dim>> points;
      double                               seconds = 0;
    };
    std::future<GridAndPoints> grid_build;
    const std::string          beside_grid = "setup and first steps, beside deal.II's grid";
    double                     engine_setup_seconds = 0;
    if (!parallel)
      {
        timer.enter_subsection(beside_grid);
        grid_build = std::async(std::launch::async, [this, generation]() {
          const auto    start = std::chrono::steady_clock::now();
          GridAndPoints built;
          built.grid   = std::make_unique<BackgroundGrid<dim>>(parameters, communicator);
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
        if (cuda_ready.valid())
          cuda_ready.get();
        engine = make_engine<dim>(parameters.backend, lattice_grid<dim>(parameters), materials,
                                  parameters.shape_function);
        engine->set_sort_interval(parameters.sort_interval);
        engine->load(host, std::move(labels));
        engine_setup_seconds = seconds_since(start);
      }
    else
      {
        timer.enter_subsection("setup: grid");
        grid = std::make_unique<BackgroundGrid<dim>>(parameters, communicator);
        timer.leave_subsection();
        timer.enter_subsection("setup: material points");
        count_points();
        points = std::make_unique<MaterialPoints<dim>>(*grid, parameters);
        points->insert(generation.get());
        timer.leave_subsection();
      }
    // Reductions over the ranks; on one rank the value itself, without an MPI call.
    auto global_max = [&](const double x) { return parallel ? max(x, communicator) : x; };
    auto global_min = [&](const double x) { return parallel ? min(x, communicator) : x; };
    auto global_sum = [&](const double x) { return parallel ? sum(x, communicator) : x; };

    // MPI: points re-sorted into cells and ranks, grid repartitioned by work.
    // Pressure averaging in parallel: a point's cell at the end of a step must be an owned
    // or ghost cell of its rank (whose cell sums the exchange covers), i.e. less than one
    // cell outside its home cell. Re-sorting at half a cell (GIMP's safe distance already)
    // leaves a step's displacement of room; the check after each step asserts it.
    const double resort_at =
      std::min(parameters.resort_distance * safe_distance_outside_home_cell(parameters.shape_function),
               parallel && parameters.pressure_averaging ? 0.5 : 1e300);
    long         n_resorts = 0, n_repartitions = 0;
    double       balanced  = 1; // imbalance right after the last repartition: what p4est achieves
    // Repartition when the work per rank is out of balance by more than the threshold and
    // by clearly more than the last repartition could reach (no futile repeats when the
    // granularity of cells forbids better). Points per rank only change at re-sorts, so
    // this is checked at the start and after each re-sort.
    auto balance = [&]() {
      if (!parallel || !(parameters.load_balance_threshold > 0))
        return false;
      const double before = points->imbalance();
      if (before <= parameters.load_balance_threshold ||
          before <= balanced + 0.5 * (parameters.load_balance_threshold - 1))
        return false;
      dealii::TimerOutput::Scope scope(timer, "repartition");
      output.finish(); // a grid output in flight reads the DoFHandler
      points->repartition();
      ++n_repartitions;
      balanced = points->imbalance();
      pcout << "  repartitioned the grid by work: max/mean work per rank " << before << " -> " << balanced
            << std::endl;
      return true;
    };
    if (parallel)
      {
        timer.enter_subsection("setup: engine");
        balance();
        engine = make_engine<dim>(parameters.backend, *grid, materials, parameters.shape_function);
        engine->set_sort_interval(parameters.sort_interval);
        engine->load(*points);
        timer.leave_subsection();
      }

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
          << output.directory() << "'" << std::endl;

    StepSettings<dim, double> settings;
    settings.scheme             = parameters.scheme;
    settings.damping            = parameters.damping;
    settings.damping_form       = parameters.damping_form;
    settings.damping_threshold  = parameters.damping_threshold;
    settings.flip_fraction      = parameters.flip_fraction;
    settings.domain_update      = parameters.domain_update;
    settings.pressure_averaging = parameters.pressure_averaging;
    settings.mass_tolerance     = 1e-12 * m_min; // nodes lighter than that carry no velocity

    double time = 0, max_speed = 0, max_removed_speed = 0, work_of_gravity = 0, dt = 0;
    long   step = 0, n_removed = 0;
    double next_output = parameters.output_interval;
    auto   last_progress = std::chrono::steady_clock::now();

    // A TimerOutput section, except while the grid thread runs (then the time counts to
    // the section entered before it started).
    auto timed = [&](const char *section, auto &&work) {
      if (grid_build.valid())
        return work();
      dealii::TimerOutput::Scope scope(timer, section);
      return work();
    };

    // The t = 0 output of a one-rank run, taken before the grid exists and written once it does.
    bool initial_output_pending = false;
    // Joins the grid thread (waits for it where it is still running): from here on the
    // grid and the handler exist and MPI may be called again.
    auto join_grid = [&]() {
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
          output.write_fields(0, *grid); // before the first step every nodal field is zero
          initial_output_pending = false;
        }
    };

    auto record_history = [&]() {
      timed("history", [&]() {
        const auto local  = engine->totals();
        const auto totals = parallel ? global_totals<dim>(local, communicator) : local;
        n_removed         = n_points_initial - totals.n_points;
        typename OutputWriter<dim>::HistoryRow row{time, dt, work_of_gravity, step, n_removed, totals};
        row.min_points_per_rank = static_cast<long>(global_min(double(local.n_points)));
        row.max_points_per_rank = static_cast<long>(global_max(double(local.n_points)));
        row.n_resorts           = n_resorts;
        row.n_repartitions      = n_repartitions;
        row.n_sent              = parallel ? static_cast<long>(sum(double(points->n_sent), communicator)) : 0;
        output.write_history(row);
      });
    };
    // Output reads a snapshot of the engine's points: no hand-over to the handler, which
    // is brought up to date only where it is needed (re-sorts, repartitions).
    auto write_output = [&]() {
      if (time == 0 && grid_build.valid())
        {
          engine->snapshot(output.next_snapshot());
          initial_output_pending = true;
          return;
        }
      join_grid();
      dealii::TimerOutput::Scope scope(timer, "output");
      engine->snapshot(output.next_snapshot());
      engine->nodal_to(*grid);
      output.write_fields(time, *grid);
    };

    write_output();
    record_history();

    const double end = parameters.end_time;
    while (time < end * (1 - 1e-12) && (parameters.max_steps == 0 || step < long(parameters.max_steps)))
      {
        if (grid_build.valid() && grid_build.wait_for(std::chrono::seconds(0)) == std::future_status::ready)
          join_grid();

        dt = parameters.adaptive_time_step ? parameters.cfl * h / (c_el + max_speed) : parameters.fixed_time_step;
        dt = std::min(dt, end - time);
        if (parameters.output_interval > 0)
          dt = std::min(dt, std::max(next_output - time, 1e-12 * end)); // land on output times

        const double ramp = parameters.gravity_ramp_time > 0 ? std::min(1.0, time / parameters.gravity_ramp_time) : 1.0;
        for (int d = 0; d < dim; ++d)
          settings.gravity[d] = ramp * parameters.gravity[d];

        if (!plastic && time >= parameters.plasticity_start_time)
          {
            plastic = true;
            for (auto &m : materials)
              m.plasticity_enabled = true;
            engine->set_materials(materials);
            pcout << "  plasticity switched on at t = " << time << " s" << std::endl;
          }

        const StepReduction<double> r = timed("MPM step", [&]() { return engine->step(settings, dt); });
        // One reduction for the next time step and the migration test: the largest
        // speed and the largest distance of a point outside its home cell.
        max_speed         = r.max_speed;
        max_removed_speed = r.max_removed_speed;
        if (parallel)
          {
            double local[3] = {r.max_speed, engine->max_distance_outside_home_cells(), r.max_removed_speed},
                   global[3];
            dealii::Utilities::MPI::max(dealii::ArrayView<const double>(local, 3), communicator,
                                        dealii::ArrayView<double>(global, 3));
            max_speed         = global[0];
            max_removed_speed = global[2];
            AssertThrow(!parameters.pressure_averaging || global[1] < 1,
                        dealii::ExcMessage("Parameter 'Solver/Pressure averaging': at t = " +
                                           dealii::Utilities::to_string(time + dt) + " s a point moved to " +
                                           dealii::Utilities::to_string(global[1]) +
                                           " cells outside the cell it was sorted into, beyond the ghost cells "
                                           "whose pressure sums are exchanged between ranks. Reduce 'Solver/CFL "
                                           "number' or the time step."));
            if (global[1] >= resort_at)
              {
                {
                  dealii::TimerOutput::Scope scope(timer, "migrate points");
                  engine->store(*points);
                  ++n_resorts;
                }
                if (balance())
                  engine->load(*points);
              }
          }
        work_of_gravity += dt * global_sum(r.gravity_power);
        time += dt;
        ++step;
        // A blow-up shows as a non-finite velocity or, with the adaptive step, as speeds that
        // shrink dt by orders of magnitude: stop with a message instead of crawling on.
        const double fastest = std::max(max_speed, max_removed_speed);
        AssertThrow(std::isfinite(max_speed) && std::isfinite(max_removed_speed) && fastest <= 1000 * c_el,
                    dealii::ExcMessage("The simulation became unstable at t = " + dealii::Utilities::to_string(time) +
                                       " s (step " + std::to_string(step) + "): a material point moves at " +
                                       dealii::Utilities::to_string(fastest) +
                                       " m/s, more than 1000 times the elastic wave speed. Reduce 'Solver/CFL "
                                       "number' or the time step, or use GIMP shape functions."));

        if (step % parameters.history_every == 0)
          record_history();
        if (parameters.output_interval > 0 && time >= next_output * (1 - 1e-12))
          {
            write_output();
            while (next_output <= time * (1 + 1e-12))
              next_output += parameters.output_interval;
          }

        const auto now = std::chrono::steady_clock::now();
        if (parameters.progress_interval > 0 &&
            std::chrono::duration<double>(now - last_progress).count() >= parameters.progress_interval)
          {
            const double elapsed = std::chrono::duration<double>(now - wall_start).count();
            const double eta     = elapsed / time * (end - time);
            pcout << "  t = " << std::setw(10) << time << " s  step " << step << "  dt " << dt << "  "
                  << std::setprecision(4) << step / elapsed << " steps/s  ETA " << eta << " s" << std::endl;
            last_progress = now;
          }
      }

    join_grid(); // a short run may end before the grid thread does
    if (step % parameters.history_every != 0)
      record_history();
    if (!(parameters.output_interval > 0 && std::abs(time - (next_output - parameters.output_interval)) < 1e-12 * end))
      write_output();
    // The handler is not brought up to date at the end: nothing reads it after the run
    // (the last output and the totals come from the engine). That hand-over cost 2.2 s of
    // the P2 run on the GPU (doc/performance.md). A checkpoint would have to do it.
    {
      dealii::TimerOutput::Scope scope(timer, "output");
      output.finish(); // the last files are complete
    }

    const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count();
    const double n_now = static_cast<double>(n_points_initial - n_removed);
    pcout << "dealii-mpm: done, t = " << time << " s after " << step << " steps in " << wall << " s wall ("
          << std::setprecision(3) << (n_now * step) / wall << " point-updates/s); " << n_removed
          << " material point(s) left the grid and were removed.\n";
    if (parallel)
      pcout << "  MPI: " << n_resorts << " re-sorts of the points into cells and ranks, "
            << static_cast<long>(sum(double(points->n_sent), communicator)) << " points migrated, "
            << n_repartitions << " repartitions; work per rank max/mean " << points->imbalance() << "\n";
    if (parallel)
      {
        // Ghost exchange per step: import + export of every ghost node's value, for each
        // array the scheme sums (MUSL: mass, momentum, force, then momentum again).
        const double ghosts = grid->partitioner->n_ghost_indices();
        const int    arrays = parameters.scheme == UpdateScheme::musl ? 3 * dim + 1 : 2 * dim + 1;
        const double bytes  = sum(double(grid->exchange_bytes_per_array()), communicator) * arrays;
        pcout << "  MPI: ghost nodes " << static_cast<long>(sum(ghosts, communicator)) << " in all, "
              << static_cast<long>(max(ghosts, communicator)) << " at most on one rank; exchange " << bytes
              << " bytes per step (" << arrays << " nodal arrays, each ghost value sent to its owner and back)\n";
      }
    pcout << "  output: " << output.n_outputs() << " outputs, " << output.task_seconds()
          << " s building and writing files on rank 0";
    if (parameters.output_in_background)
      pcout << " (background threads; the run waited " << output.waited_seconds() << " s for them)";
    pcout << "\n";
    pcout
          << "  results: " << output.directory() << "/particles.pvd, " << output.directory()
          << "/grid.pvd, " << output.directory() << "/history.csv" << std::endl;
  }

  void run_simulation(const Parameters &parameters, MPI_Comm communicator)
  {
    if (parameters.dim == 2)
      Simulator<2>(parameters, communicator).run();
    else
      Simulator<3>(parameters, communicator).run();
  }

  template class Simulator<2>;
  template class Simulator<3>;
} // namespace mpm
