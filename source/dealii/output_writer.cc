#include <mpm/dealii/output_writer.h>

#include <algorithm>

#include <deal.II/base/exceptions.h>
#include <deal.II/base/mpi.h>
#include <deal.II/base/utilities.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <functional>
#include <iomanip>
#include <memory>
#include <regex>
#include <sstream>

#ifdef __linux__
#  include <sys/resource.h>
#  include <sys/syscall.h>
#  include <unistd.h>
#endif

namespace mpm
{
  namespace
  {
    using Ranges = std::vector<std::tuple<unsigned int, unsigned int, std::string,
                                          dealii::DataComponentInterpretation::DataComponentInterpretation>>;

    // Piece and record names as DataOutInterface::write_vtu_with_pvtu_record writes them
    // (one piece per rank: name_CCCCC.R.vtu and name_CCCCC.pvtu), with K pieces per rank
    // numbered R K + k.
    std::string piece_name(const std::string &name, const unsigned int counter, const unsigned int piece,
                           const unsigned int n_pieces)
    {
      return name + "_" + dealii::Utilities::int_to_string(counter, 5) + "." +
             dealii::Utilities::int_to_string(piece, dealii::Utilities::needed_digits(n_pieces - 1)) + ".vtu";
    }
    std::string record_name(const std::string &name, const unsigned int counter)
    {
      return name + "_" + dealii::Utilities::int_to_string(counter, 5) + ".pvtu";
    }

    // One .vtu piece (number piece of n_pieces); with write_records also the .pvtu record
    // of all pieces and the .pvd time series (rank 0, once per output).
    template <int patch_dim, int spacedim>
    void write_piece(const dealii::DataOutInterface<patch_dim, spacedim> &out, const std::string &directory,
                     const std::string &name, const unsigned int counter, const unsigned int piece,
                     const unsigned int n_pieces, const bool write_records,
                     const std::vector<std::pair<double, std::string>> &records)
    {
      const std::string file_name = directory + "/" + piece_name(name, counter, piece, n_pieces);
      std::ofstream     file(file_name);
      AssertThrow(file, dealii::ExcMessage("Parameter 'Output/Directory': cannot write '" + file_name + "'."));
      out.write_vtu(file);
      AssertThrow(file, dealii::ExcMessage("Parameter 'Output/Directory': writing '" + file_name + "' failed."));
      if (!write_records)
        return;
      std::vector<std::string> pieces;
      for (unsigned int r = 0; r < n_pieces; ++r)
        pieces.push_back(piece_name(name, counter, r, n_pieces));
      std::ofstream pvtu(directory + "/" + record_name(name, counter));
      out.write_pvtu_record(pvtu, pieces);
      std::ofstream pvd(directory + "/" + name + ".pvd");
      dealii::DataOutBase::write_pvd_record(pvd, records);
    }

    // A background output thread gives way to the GPU's steps: where the writing threads are as
    // many as the cores, the thread that queues the steps would otherwise wait for a core.
    // Linux: the calling thread's nice value, which the threads it starts inherit; elsewhere,
    // and with MPM_OUTPUT_YIELD=0 (for measuring), nothing. Not for the CPU backend, whose
    // step threads (TBB's, started on first use, perhaps from such a thread) must not inherit it.
    void yield_to_the_steps()
    {
#ifdef __linux__
      static const bool yield = [] {
        const char *v = std::getenv("MPM_OUTPUT_YIELD");
        return !(v != nullptr && v[0] == '0');
      }();
      if (yield)
        setpriority(PRIO_PROCESS, static_cast<id_t>(syscall(SYS_gettid)), 10); // no error if refused
#endif
    }

    // Runs the tasks on their own threads and waits for all; rethrows the first error.
    void run_all(std::vector<std::function<void()>> &tasks)
    {
      std::vector<std::future<void>> running;
      for (unsigned int k = 1; k < tasks.size(); ++k)
        running.push_back(std::async(std::launch::async, tasks[k]));
      std::exception_ptr error;
      try
        {
          if (!tasks.empty())
            tasks[0]();
        }
      catch (...)
        {
          error = std::current_exception();
        }
      for (auto &task : running)
        try
          {
            task.get();
          }
        catch (...)
          {
            if (!error)
              error = std::current_exception();
          }
      if (error)
        std::rethrow_exception(error);
    }

    // Full-precision table of one rank's points: id, position, every property.
    template <int dim>
    void write_point_table(const PointSnapshot<dim> &snapshot, const std::string &file_name)
    {
      std::ofstream table(file_name);
      AssertThrow(table, dealii::ExcMessage("Parameter 'Output/Directory': cannot write '" + file_name + "'."));
      const PropertyLayout<dim> layout = snapshot.layout();
      const auto                names  = layout.names();
      table << "id";
      for (int d = 0; d < dim; ++d)
        table << ",position_" << "xyz"[d];
      std::vector<unsigned int> seen(names.size(), 0);
      for (unsigned int k = 0; k < names.size(); ++k)
        {
          // Vector properties repeat their name: number their components.
          unsigned int repeats = 0;
          for (unsigned int j = 0; j < names.size(); ++j)
            repeats += names[j] == names[k];
          table << ',' << names[k];
          if (repeats > 1)
            table << '_' << "xyz"[seen[k]];
          for (unsigned int j = k + 1; j < names.size(); ++j)
            if (names[j] == names[k])
              seen[j] = seen[k] + 1;
        }
      table << '\n' << std::setprecision(17);
      const auto         &p = snapshot.points;
      std::vector<double> values(layout.n_properties());
      for (int i = 0; i < p.size(); ++i)
        {
          if (p.material[i] < 0)
            continue; // left the grid
          snapshot.properties(layout, i, values.data());
          table << snapshot.labels->id[i];
          for (int d = 0; d < dim; ++d)
            table << ',' << p.position[d][i];
          for (const double value : values)
            table << ',' << value;
          table << '\n';
        }
    }
  } // namespace

  template <int dim>
  GridSnapshot<dim>::GridSnapshot(const BackgroundGrid<dim> &grid, const unsigned int rank)
    : rank(rank)
  {
    for (const auto &cell : grid.dof_handler.active_cell_iterators())
      if (cell->is_locally_owned() && grid.is_fine(cell)) // (coarse away from the material: no mass, no nodes)
        cells.push_back(cell);
    cells_per_grid_cell = grid.cells_per_grid_cell;
    if (cells_per_grid_cell > 1)
      {
        lattice_to_node = grid.lattice_node_map();
        h               = grid.h;
        for (int d = 0; d < dim; ++d)
          origin[d] = grid.origin[d];
      }
    nodal.push_back(grid.mass);
    for (int d = 0; d < dim; ++d)
      nodal.push_back(grid.velocity[d]);
    for (auto &field : nodal)
      field.update_ghost_values(); // as DataOut::add_data_vector's copy does
  }

  template <int dim, typename Real>
  typename GridSnapshot<dim>::LatticeCells lattice_cells_with_mass(const GridView<dim, Real> &nodes,
                                                                   const std::vector<long>    &lattice_of_node,
                                                                   const double origin[dim], const double h)
  {
    const int *n_cells = nodes.n_cells;
    // The cells around every node with mass: the node is vertex `corner` of the cell whose
    // lower corner is the node minus corner's bits.
    std::vector<long> cells;
    for (std::size_t node = 0; node < lattice_of_node.size(); ++node)
      {
        if (lattice_of_node[node] < 0 || nodes.mass[node] == 0)
          continue;
        int idx[dim];
        lattice_node_coordinates<dim>(n_cells, lattice_of_node[node], idx);
        for (int corner = 0; corner < (1 << dim); ++corner)
          {
            long cell = 0;
            bool in   = true;
            for (int d = dim - 1; d >= 0; --d)
              {
                const int i = idx[d] - ((corner >> d) & 1);
                in          = in && i >= 0 && i < n_cells[d];
                cell        = cell * n_cells[d] + i;
              }
            if (in)
              cells.push_back(cell);
          }
      }
    std::sort(cells.begin(), cells.end());
    cells.erase(std::unique(cells.begin(), cells.end()), cells.end());
    constexpr int                            n_vertices = 1 << dim;
    typename GridSnapshot<dim>::LatticeCells out;
    out.h = h;
    out.lower_corner.resize(cells.size());
    out.vertex_values.assign(cells.size() * n_vertices * (1 + dim), 0.0);
    for (std::size_t c = 0; c < cells.size(); ++c)
      {
        int  idx[dim];
        long rest = cells[c];
        for (int d = 0; d < dim; ++d)
          {
            idx[d] = static_cast<int>(rest % n_cells[d]);
            rest /= n_cells[d];
            out.lower_corner[c][d] = origin[d] + idx[d] * h;
          }
        for (int v = 0; v < n_vertices; ++v)
          {
            int vertex[dim];
            for (int d = 0; d < dim; ++d)
              vertex[d] = idx[d] + ((v >> d) & 1);
            const int node = nodes.node(vertex);
            if (node < 0) // not kept: no point reaches it
              continue;
            double *values = &out.vertex_values[(c * n_vertices + v) * (1 + dim)];
            values[0]      = nodes.mass[node];
            for (int d = 0; d < dim; ++d)
              values[1 + d] = nodes.velocity[d][node];
          }
      }
    return out;
  }

  template <int dim>
  GridSnapshot<dim>::GridSnapshot(LatticeCells cells)
    : lattice_cells(std::move(cells))
  {}

  template <int dim>
  void GridDataOut<dim>::build_patches(const GridSnapshot<dim> &snapshot, const int begin, const int end)
  {
    constexpr unsigned int n_vertices = dealii::GeometryInfo<dim>::vertices_per_cell;
    const int              last       = end < 0 ? snapshot.n_cells() : end;
    patches.clear();
    patches.resize(std::max(last - begin, 0));
    if (snapshot.cells.empty()) // the engine's lattice cells (no deal.II grid)
      {
        const auto        &lattice  = snapshot.lattice_cells;
        const unsigned int n_fields = 1 + dim;
        for (int c = begin; c < last; ++c)
          {
            auto &patch          = patches[c - begin];
            patch.patch_index    = c - begin;
            patch.reference_cell = dealii::ReferenceCells::get_hypercube<dim>();
            patch.data.reinit(n_fields + 1, n_vertices);
            for (unsigned int v = 0; v < n_vertices; ++v)
              {
                patch.vertices[v] = lattice.lower_corner[c];
                for (int d = 0; d < dim; ++d)
                  if ((v >> d) & 1)
                    patch.vertices[v][d] += lattice.h;
                for (unsigned int k = 0; k < n_fields; ++k)
                  patch.data(k, v) = lattice.vertex_values[(std::size_t(c) * n_vertices + v) * n_fields + k];
                patch.data(n_fields, v) = snapshot.rank;
              }
          }
        return;
      }
    const unsigned int n_nodal = snapshot.nodal.size();
    if (snapshot.cells_per_grid_cell > 1) // a patch per lattice cell, its deal.II cell's in turn
      {
        const int k = snapshot.cells_per_grid_cell, per_cell = dealii::Utilities::pow(k, dim);
        for (int c = begin; c < last; ++c)
          {
            const auto              &cell  = snapshot.cells[c / per_cell];
            const dealii::Point<dim> lower = cell->vertex(0);
            int                      first[dim];
            for (int d = 0, rest = c % per_cell; d < dim; ++d, rest /= k)
              first[d] = static_cast<int>(std::lround((lower[d] - snapshot.origin[d]) / snapshot.h)) + rest % k;
            auto &patch          = patches[c - begin];
            patch.patch_index    = c - begin;
            patch.reference_cell = dealii::ReferenceCells::get_hypercube<dim>();
            patch.data.reinit(n_nodal + 1, n_vertices);
            for (unsigned int v = 0; v < n_vertices; ++v)
              {
                int node[dim];
                for (int d = 0; d < dim; ++d)
                  {
                    node[d]              = first[d] + ((v >> d) & 1);
                    patch.vertices[v][d] = snapshot.origin[d] + node[d] * snapshot.h;
                  }
                const int local = (*snapshot.lattice_to_node)(node);
                for (unsigned int f = 0; f < n_nodal; ++f)
                  patch.data(f, v) = snapshot.nodal[f].local_element(local);
                patch.data(n_nodal, v) = snapshot.rank;
              }
          }
        return;
      }
    for (int c = begin; c < last; ++c)
      {
        const auto &cell  = snapshot.cells[c];
        auto       &patch = patches[c - begin];
        patch.patch_index    = c - begin;
        patch.reference_cell = dealii::ReferenceCells::get_hypercube<dim>();
        patch.data.reinit(n_nodal + 1, n_vertices);
        // DataOut's points of a patch without subdivisions are the cell's vertices in
        // deal.II's (lexicographic) vertex order.
        for (unsigned int v = 0; v < n_vertices; ++v)
          {
            patch.vertices[v]                         = cell->vertex(v);
            const dealii::types::global_dof_index dof = cell->vertex_dof_index(v, 0);
            for (unsigned int k = 0; k < n_nodal; ++k)
              patch.data(k, v) = snapshot.nodal[k](dof);
            patch.data(n_nodal, v) = snapshot.rank;
          }
      }
  }

  template <int dim>
  std::vector<std::string> GridDataOut<dim>::get_dataset_names() const
  {
    std::vector<std::string> names = {"nodal_mass"};
    for (int d = 0; d < dim; ++d)
      names.push_back(std::string("nodal_velocity_") + "xyz"[d]);
    names.push_back("subdomain");
    return names;
  }

  template <int dim>
  void PointDataOut<dim>::build_patches(const PointSnapshot<dim> &snapshot, const int begin, const int end)
  {
    const auto        &p            = snapshot.points;
    const PropertyLayout<dim> layout = snapshot.layout();
    const unsigned int n_properties  = layout.n_properties();
    state_variable_names             = snapshot.labels->state_variable_names;
    carried                          = p.fields;
    const auto fields                = layout.fields();
    components.clear();
    for (unsigned int c = 0; c < n_properties; ++c)
      if (selected_fields.empty() ||
          std::find(selected_fields.begin(), selected_fields.end(), fields[c]) != selected_fields.end())
        components.push_back(c);
    const int          last         = end < 0 ? p.size() : end;
    unsigned int       n            = 0;
    for (int i = begin; i < last; ++i)
      n += p.material[i] >= 0;
    patches.clear();
    patches.resize(n);
    std::vector<double> values(n_properties);
    unsigned int        k = 0;
    for (int i = begin; i < last; ++i)
      {
        if (p.material[i] < 0)
          continue; // left the grid
        auto &patch = patches[k];
        for (int d = 0; d < dim; ++d)
          patch.vertices[0][d] = p.position[d][i];
        patch.patch_index = k;
        patch.data.reinit(components.size() + 1, 1);
        patch.data(0, 0) = snapshot.labels->id[i];
        snapshot.properties(layout, i, values.data());
        for (unsigned int j = 0; j < components.size(); ++j)
          patch.data(j + 1, 0) = values[components[j]];
        ++k;
      }
  }

  template <int dim>
  std::vector<std::string> PointDataOut<dim>::get_dataset_names() const
  {
    std::vector<std::string> names = {"id"};
    const auto               all   = PropertyLayout<dim>(carried, state_variable_names).names();
    for (const unsigned int c : components)
      names.push_back(all[c]);
    return names;
  }

  // Consecutive vector components of one name form one range, as in Particles::DataOut.
  template <int dim>
  Ranges PointDataOut<dim>::get_nonscalar_data_ranges() const
  {
    using namespace dealii::DataComponentInterpretation;
    const auto names = get_dataset_names();
    std::vector<DataComponentInterpretation> kinds = {component_is_scalar};
    const auto all = PropertyLayout<dim>(carried, state_variable_names).interpretations();
    for (const unsigned int c : components)
      kinds.push_back(all[c]);
    Ranges ranges;
    for (unsigned int i = 0; i < names.size();)
      if (kinds[i] == component_is_part_of_vector)
        {
          unsigned int n = 1;
          while (i + n < names.size() && kinds[i + n] == component_is_part_of_vector && names[i + n] == names[i])
            ++n;
          ranges.emplace_back(i, i + n - 1, names[i], component_is_part_of_vector);
          i += n;
        }
      else
        ++i;
    return ranges;
  }

  template <int dim>
  OutputWriter<dim>::OutputWriter(const OutputSettings &settings, const bool yield_to_steps, MPI_Comm communicator,
                                  const bool resuming)
    : communicator(communicator)
    , rank(dealii::Utilities::MPI::this_mpi_process(communicator))
    , n_ranks(dealii::Utilities::MPI::n_mpi_processes(communicator))
    , output_directory(settings.directory)
    , write_grid(settings.write_grid_fields)
    , write_particles(settings.write_particles)
    , write_table(settings.write_particle_table)
    , background(settings.in_background)
    , particle_fields(settings.particle_fields)
    , pieces_per_rank(settings.files_per_rank)
    , yield_to_steps(yield_to_steps)
  {
    if (output_directory.empty())
      output_directory = ".";
    using Flags = dealii::DataOutBase::VtkFlags;
    vtk_flags.compression_level = settings.compression == "no compression"   ? Flags::no_compression :
                                  settings.compression == "best compression" ? Flags::best_compression :
                                  settings.compression == "default"          ? Flags::default_compression :
                                                                               Flags::best_speed;
    // Rank 0 creates the folder and the history; every rank learns whether that worked,
    // so that a bad Output/Directory stops all ranks with one message instead of a hang.
    std::string problem;
    if (rank == 0)
      {
        std::error_code error;
        std::filesystem::create_directories(output_directory, error);
        if (error)
          problem = "cannot create '" + output_directory + "': " + error.message();
        else
          {
            // A resumed run continues the rows of the stopped one (resume()): kept aside here.
            // Where a file is already kept aside, a resume failed after this point (a damaged
            // checkpoint): that one holds the rows, and the history.csv beside it only a header.
            std::error_code ignored;
            if (resuming && !std::filesystem::exists(output_directory + "/history.csv.stopped"))
              std::filesystem::rename(output_directory + "/history.csv", output_directory + "/history.csv.stopped",
                                      ignored);
            history.open(output_directory + "/history.csv");
            if (!history)
              problem = "cannot write to '" + output_directory + "'.";
          }
      }
    problem = dealii::Utilities::MPI::broadcast(communicator, problem, 0);
    AssertThrow(problem.empty(), dealii::ExcMessage("Parameter 'Output/Directory': " + problem));
    if (rank == 0)
      {
        history << "time,dt,step,kinetic_energy,work_of_gravity,total_mass";
        for (int d = 0; d < dim; ++d)
          history << ",momentum_" << "xyz"[d];
        history << ",n_points,n_removed";
        for (int d = 0; d < dim; ++d)
          history << ",min_" << "xyz"[d];
        for (int d = 0; d < dim; ++d)
          history << ",max_" << "xyz"[d];
        history << ",min_points_per_rank,max_points_per_rank,n_resorts,n_repartitions,n_sent,removed_mass,mass_balance";
        history << "\n" << std::setprecision(16);
      }
  }

  template <int dim>
  void OutputWriter<dim>::resume(const Records &records, const long step)
  {
    counter          = records.n_outputs;
    grid_records     = records.grid;
    particle_records = records.particles;
    if (rank != 0)
      return;
    // The rows of the run so far, from the file of the stopped run (where there is one: the
    // output folder may be a new one), up to the checkpoint's step.
    const std::string  file = output_directory + "/history.csv";
    std::ifstream      old(file + ".stopped");
    std::string        line;
    std::getline(old, line); // the header, written anew by the constructor
    while (std::getline(old, line))
      {
        std::istringstream fields(line);
        std::string        time, dt, row_step;
        if (std::getline(fields, time, ',') && std::getline(fields, dt, ',') && std::getline(fields, row_step, ',') &&
            std::stol(row_step) <= step)
          history << line << '\n';
      }
    history.flush();
    old.close();
    std::error_code error;
    std::filesystem::remove(file + ".stopped", error);
  }

  template <int dim>
  OutputWriter<dim>::~OutputWriter()
  {
    for (auto &task : in_flight)
      task.wait();
  }

  template <int dim>
  void OutputWriter<dim>::finish()
  {
    std::vector<std::future<void>> tasks;
    tasks.swap(in_flight);
    const auto start = std::chrono::steady_clock::now();
    for (auto &task : tasks)
      task.wait();
    waited += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    for (auto &task : tasks)
      task.get(); // rethrows the first error
  }

  template <int dim>
  PointSnapshot<dim> &OutputWriter<dim>::next_snapshot()
  {
    finish();
    snapshot.wait_for_points(); // a download that no task read (neither particles nor table written)
    return snapshot;
  }

  template <int dim>
  void OutputWriter<dim>::write_fields(const double time, BackgroundGrid<dim> &grid)
  {
    finish();
    // What the background tasks read is copied now. DataOut::add_data_vector makes its own
    // ghosted copy of each vector (MPI: here, on this thread); build_patches then reads
    // those copies and the DoFHandler as it is (it changes only in a repartition, which
    // calls finish() first) and does no communication.
    write(time, write_grid ? std::make_shared<const GridSnapshot<dim>>(grid, rank) : nullptr);
  }

  template <int dim>
  void OutputWriter<dim>::write_fields(const double time, typename GridSnapshot<dim>::LatticeCells cells)
  {
    finish();
    write(time, write_grid ? std::make_shared<const GridSnapshot<dim>>(std::move(cells)) : nullptr);
  }

  template <int dim>
  void OutputWriter<dim>::write(const double time, std::shared_ptr<const GridSnapshot<dim>> grid_snapshot)
  {
    if (write_grid)
      grid_records.emplace_back(time, record_name("grid", counter));
    if (write_particles)
      particle_records.emplace_back(time, record_name("particles", counter));

    // Two tasks, each reading only what it owns (the snapshot is not touched until finish());
    // each writes its Output/Files per rank pieces on as many threads.
    const unsigned int K = pieces_per_rank;
    auto grid_task = [this, grid_snapshot, K, counter = counter, records = grid_records]() {
      std::vector<std::function<void()>> writes;
      const int                          n = grid_snapshot->n_cells();
      for (unsigned int k = 0; k < K; ++k)
        writes.emplace_back([&, k]() {
          GridDataOut<dim> out;
          out.set_flags(vtk_flags);
          out.build_patches(*grid_snapshot, int(long(n) * k / K), int(long(n) * (k + 1) / K));
          write_piece(out, output_directory, "grid", counter, rank * K + k, n_ranks * K, rank == 0 && k == 0,
                      records);
        });
      run_all(writes);
    };
    auto point_task = [this, K, counter = counter, records = particle_records]() {
      snapshot.wait_for_points();
      if (write_particles)
        {
          std::vector<std::function<void()>> writes;
          const int                          n = snapshot.points.size();
          for (unsigned int k = 0; k < K; ++k)
            writes.emplace_back([&, k]() {
              PointDataOut<dim> out;
              out.set_flags(vtk_flags);
              out.select_fields(particle_fields);
              out.build_patches(snapshot, int(long(n) * k / K), int(long(n) * (k + 1) / K));
              write_piece(out, output_directory, "particles", counter, rank * K + k, n_ranks * K,
                          rank == 0 && k == 0, records);
            });
          run_all(writes);
        }
      if (write_table)
        {
          std::ostringstream name;
          name << output_directory << "/particle_table_" << std::setw(5) << std::setfill('0') << counter << '.'
               << rank << ".csv";
          write_point_table(snapshot, name.str());
        }
    };
    std::vector<std::function<void()>> tasks;
    if (write_grid)
      tasks.emplace_back(grid_task);
    if (write_particles || write_table)
      tasks.emplace_back(point_task);
    for (auto &task : tasks)
      {
        auto timed = [this, task]() {
          const auto start = std::chrono::steady_clock::now();
          task();
          task_nanoseconds += std::chrono::duration_cast<std::chrono::nanoseconds>(
                                std::chrono::steady_clock::now() - start)
                                .count();
        };
        if (background)
          in_flight.push_back(std::async(std::launch::async, [timed, yield = yield_to_steps]() {
            if (yield)
              yield_to_the_steps();
            timed();
          }));
        else
          timed();
      }
    ++counter;
  }

  template <int dim>
  void OutputWriter<dim>::write_history(const HistoryRow &r)
  {
    if (rank != 0) // no MPI call: one-rank runs write history while the grid is built on a thread
      return;
    history << r.time << ',' << r.dt << ',' << r.step << ',' << r.totals.kinetic_energy << ','
            << r.work_of_gravity << ',' << r.totals.mass;
    for (int d = 0; d < dim; ++d)
      history << ',' << r.totals.momentum[d];
    history << ',' << r.totals.n_points << ',' << r.n_removed;
    for (int d = 0; d < dim; ++d)
      history << ',' << r.totals.lower[d];
    for (int d = 0; d < dim; ++d)
      history << ',' << r.totals.upper[d];
    history << ',' << r.min_points_per_rank << ',' << r.max_points_per_rank << ',' << r.n_resorts << ','
            << r.n_repartitions << ',' << r.n_sent << ',' << r.removed_mass << ',' << r.mass_balance;
    history << '\n';
    history.flush();
  }

  template <int dim>
  std::vector<std::string> OutputWriter<dim>::files_of_earlier_runs() const
  {
    std::vector<std::string> found;
    if (rank != 0)
      return found;
    // Our names: KIND.pvd, KIND_NNNNN.pvtu, KIND_NNNNN.P.vtu, particle_table_NNNNN.R.csv.
    static const std::regex numbered(R"(^(particles|grid|particle_table)_([0-9]{5})\.(pvtu|[0-9]+\.vtu|[0-9]+\.csv)$)");
    static const std::regex record(R"(^(particles|grid)\.pvd$)");
    const auto written = [&](const std::string &kind) {
      return kind == "particles" ? write_particles : kind == "grid" ? write_grid : write_table;
    };
    std::error_code error;
    for (const auto &entry : std::filesystem::directory_iterator(output_directory, error))
      {
        const std::string name = entry.path().filename().string();
        std::smatch       match;
        if (std::regex_match(name, match, numbered))
          {
            const bool table_file = match[3].str().size() > 4 && match[3].str().substr(match[3].str().size() - 4) == ".csv";
            if ((match[1] == "particle_table") != table_file)
              continue; // not a name this writer makes (e.g. particles_00001.0.csv)
            if (!written(match[1]) || std::stoul(match[2]) >= counter)
              found.push_back(name);
          }
        else if (std::regex_match(name, match, record) && (!written(match[1]) || counter == 0))
          found.push_back(name);
      }
    std::sort(found.begin(), found.end());
    return found;
  }

  template struct GridSnapshot<2>;
  template struct GridSnapshot<3>;
  template typename GridSnapshot<2>::LatticeCells lattice_cells_with_mass(const GridView<2, double> &,
                                                                          const std::vector<long> &, const double *,
                                                                          double);
  template typename GridSnapshot<3>::LatticeCells lattice_cells_with_mass(const GridView<3, double> &,
                                                                          const std::vector<long> &, const double *,
                                                                          double);
  template typename GridSnapshot<2>::LatticeCells lattice_cells_with_mass(const GridView<2, float> &,
                                                                          const std::vector<long> &, const double *,
                                                                          double);
  template typename GridSnapshot<3>::LatticeCells lattice_cells_with_mass(const GridView<3, float> &,
                                                                          const std::vector<long> &, const double *,
                                                                          double);
  template class GridDataOut<2>;
  template class GridDataOut<3>;
  template class OutputWriter<2>;
  template class OutputWriter<3>;
} // namespace mpm
