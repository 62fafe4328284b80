// A Simulator's checkpoints: writing one, and resuming a run from one (doc/checkpoints.md).
#include "simulator_state.h"

namespace mpm
{
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
      AssertThrow(r.strength_divisor == p.strength_divisor,
                  dealii::ExcMessage(of + "was written with the materials' strengths divided by " +
                                     std::to_string(r.strength_divisor) + " (a pre-failure analysis's hand-over); "
                                     "this run divides them by " + std::to_string(p.strength_divisor) +
                                     ". Resume it with the parameter file of the run that wrote it."));
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
    check_backend(parameters.backend.name);
    std::future<void> cuda_ready;
    if (parameters.backend.name == "cuda")
      cuda_ready = start_cuda_initialisation(s.communicator);

    s.h                 = parameters.cell_size;
    s.c_el              = r.elastic_wave_speed;
    s.losses.m_min             = r.smallest_point_mass;
    s.time              = r.time;
    s.dt                = r.dt;
    s.max_speed         = r.max_speed;
    s.max_removed_speed = r.max_removed_speed;
    s.work_of_gravity   = r.work_of_gravity;
    s.migration.balanced          = r.balanced;
    s.next_output       = r.next_output;
    s.step              = r.step;
    s.losses.n_points_initial  = r.n_points_initial;
    s.n_removed         = r.n_removed;
    s.losses.initial_mass      = r.initial_mass;
    s.migration.n_resorts         = r.n_resorts;
    s.migration.n_repartitions    = r.n_repartitions;
    s.equilibration     = r.equilibration;
    s.plastic           = r.plastic;
    s.materials         = parameters.materials;
    for (auto &m : s.materials)
      m.plasticity_enabled = s.plastic;

    s.output = std::make_unique<OutputWriter<dim>>(parameters.output, parameters.backend.name == "cuda", s.communicator,
                                                  /*resuming=*/true);
    s.output->resume({r.n_outputs, r.grid_records, r.particle_records}, r.step);

    // Each rank reads every rank's points (one rank: all, including those that left the grid,
    // as the engine held them); on several ranks the grid is partitioned by their work as it is
    // built, as the grid of a run starting, and each rank keeps the points in its cells.
    const unsigned int rank = dealii::Utilities::MPI::this_mpi_process(s.communicator);
    s.timer.enter_subsection("setup: grid");
    PointSnapshot<dim> saved =
      checkpoint::read_points<dim>(folder, r, [&](const HostPoints<dim, double> &p, const int i) {
        if (!s.parallel || p.material[i] >= 0)
          return true;
        if (rank == 0) // left the grid (saved by one rank): dropped here, counted once
          {
            ++s.losses.n_dropped;
            s.losses.dropped_mass += p.mass[i];
          }
        return false;
      });
    if (s.builds_dealii_grid())
      {
        s.grid   = std::make_unique<BackgroundGrid<dim>>(parameters, s.communicator,
                                                       std::vector<const HostPoints<dim, double> *>{&saved.points});
        s.points = std::make_unique<MaterialPoints<dim>>(*s.grid, parameters);
      }
    if (s.parallel)
      saved = saved.selected([&](const int i) {
        double x[dim];
        for (int d = 0; d < dim; ++d)
          x[d] = saved.points.position[d][i];
        return s.grid->owned_cell(s.grid->lattice_cell_of(x)) != s.grid->triangulation.end();
      });
    AssertThrow(saved.points.n_state_variables() == static_cast<int>(parameters.state_variable_names().size()),
                dealii::ExcMessage("--resume: the points of '" + folder + "': " +
                                   state_variable_count_mismatch(saved.points.n_state_variables(),
                                                                 parameters.state_variable_names())));
    if (s.points) // not on one rank with Grid/Nodes = near material
      {
        if (!s.parallel)
          s.points->replace(saved);
        s.points->n_sent = rank == 0 ? r.n_sent : 0;
      }
    if (rank == 0) // the sums over ranks
      {
        s.losses.n_dropped    += r.n_dropped;
        s.losses.dropped_mass += r.dropped_mass;
      }
    s.timer.leave_subsection();

    s.timer.enter_subsection("setup: engine");
    if (cuda_ready.valid())
      cuda_ready.get();
    s.start_from(saved);
    s.set_resort_distance();
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


  void request_checkpoint_and_stop()
  {
    stop_requested.store(true);
  }

  template <int dim>
  RunState Simulator<dim>::State::run_state() const
  {
    RunState r;
    r.dim                  = dim;
    r.n_ranks              = n_ranks;
    r.lower                = parameters.lower;
    r.upper                = parameters.upper;
    r.cell_size            = parameters.cell_size;
    r.n_materials          = parameters.materials.size();
    r.state_variable_names = parameters.state_variable_names();
    r.strength_divisor     = parameters.strength_divisor;
    r.time                 = time;
    r.dt                   = dt;
    r.max_speed            = max_speed;
    r.max_removed_speed    = max_removed_speed;
    r.work_of_gravity      = work_of_gravity;
    r.elastic_wave_speed   = c_el;
    r.smallest_point_mass  = losses.m_min;
    r.balanced             = migration.balanced;
    r.next_output          = next_output;
    r.step                 = step;
    r.n_points_initial     = losses.n_points_initial;
    r.n_removed            = n_removed;
    r.initial_mass         = losses.initial_mass;
    r.n_dropped            = parallel ? static_cast<long>(sum(double(losses.n_dropped), communicator)) : losses.n_dropped;
    r.dropped_mass         = parallel ? sum(losses.dropped_mass, communicator) : losses.dropped_mass;
    r.n_resorts            = migration.n_resorts;
    r.n_repartitions       = migration.n_repartitions;
    r.n_sent               = parallel ? static_cast<long>(sum(double(points->n_sent), communicator)) : 0;
    r.plastic              = plastic;
    r.equilibration        = equilibration;
    const auto records     = output->records();
    r.n_outputs            = records.n_outputs;
    r.grid_records         = records.grid;
    r.particle_records     = records.particles;
    return r;
  }

  template <int dim>
  std::string Simulator<dim>::State::write_checkpoint()
  {
    settle();
    join_grid();
    dealii::TimerOutput::Scope scope(timer, "checkpoint");
    const auto                 started = std::chrono::steady_clock::now();
    PointSnapshot<dim>         snapshot;
    if (parallel)
      {
        resort(); // every point on the rank owning its cell
      }
    engine->snapshot(snapshot);
    last_checkpoint = checkpoint::write<dim>(parameters.checkpoint.directory, run_state(), snapshot,
                                             parameters.checkpoint.keep, communicator);
    start_from(snapshot);
    last_checkpoint_wall = std::chrono::steady_clock::now();
    last_checkpoint_step = step;
    pcout << "  checkpoint at t = " << time << " s (step " << step << "): " << last_checkpoint << " ("
          << std::chrono::duration<double>(last_checkpoint_wall - started).count() << " s)" << std::endl;
    return last_checkpoint;
  }

  template <int dim>
  void Simulator<dim>::State::start_from(const PointSnapshot<dim> &saved)
  {
    if (parallel)
      {
        points->replace(saved);
        refine_near_material();
        partition_by_current_work();
        if (!engine)
          engine = make_engine<dim>(parameters.backend.name, *grid, materials, parameters.shape_function,
                                    parameters.backend.single_precision, parameters.active_block_cells);
        engine->load(*points);
      }
    else
      {
        if (!engine)
          engine = make_engine<dim>(parameters.backend.name, lattice_grid<dim>(parameters, parameters.active_block_cells == 0), materials,
                                    parameters.shape_function, parameters.active_block_cells,
                                    parameters.backend.single_precision);
        engine->load(saved.points, saved.labels); // in the saved order: the same sums as before
      }
    engine->set_sort_interval(parameters.backend.sort_interval);
  }

  template std::string Simulator<2>::write_checkpoint();
  template bool Simulator<2>::stopped() const;
  template void Simulator<2>::resume(const std::string &);
  template std::string Simulator<3>::write_checkpoint();
  template bool Simulator<3>::stopped() const;
  template void Simulator<3>::resume(const std::string &);
  template RunState Simulator<2>::State::run_state() const;
  template RunState Simulator<3>::State::run_state() const;
  template std::string Simulator<2>::State::write_checkpoint();
  template std::string Simulator<3>::State::write_checkpoint();
  template void Simulator<2>::State::start_from(const PointSnapshot<2> &);
  template void Simulator<3>::State::start_from(const PointSnapshot<3> &);
} // namespace mpm
