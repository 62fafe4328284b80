// Backend = cuda (include/mpm/dealii/cuda_engine.h). Compiled by the C++ compiler in
// every build; the device work is in the library mpm_cuda_engine (source/cuda/*.cu),
// linked when the project is configured with -DMPM_WITH_CUDA=ON (MPM_CUDA_ENGINE).
#include <mpm/dealii/cuda_engine.h>

#include <deal.II/base/exceptions.h>

#include <deal.II/base/mpi.h>
#include <deal.II/base/parallel.h>

#ifdef MPM_CUDA_ENGINE
#  include <mpm/cuda/device_engine.h>

#  if __has_include(<mpi-ext.h>)
#    include <mpi-ext.h> // Open MPI: MPIX_CUDA_AWARE_SUPPORT
#  endif

#  include <algorithm>
#  include <chrono>
#  include <cstdlib>
#  include <iostream>
#  include <map>
#  include <type_traits>
#endif

namespace mpm
{
#ifdef MPM_CUDA_ENGINE
  namespace
  {
    // The host side of the device's nodal exchange on several ranks: the device packs the
    // exchanged entries in the order of the grid's exchanged_local_nodes() (cells:
    // exchanged_local_cells()), entry by entry, and deal.II's Partitioner sums them over the
    // ranks from there (BackgroundGrid::sum_packed_nodes: only the owned entries are copied
    // on the host, the ghosts go to MPI from the packed buffer itself).
    template <int dim>
    class GridExchange : public cuda::NodalExchange
    {
    public:
      explicit GridExchange(const BackgroundGrid<dim> &grid)
        : grid(grid)
        , nodes(grid.exchanged_local_nodes())
        , cells(grid.exchanged_local_cells())
      {}

      std::vector<int> exchanged_nodes() const override { return std::vector<int>(nodes.begin(), nodes.end()); }

      std::vector<long> exchanged_cells() const override
      {
        std::vector<long> lattice(cells.size());
        for (std::size_t j = 0; j < cells.size(); ++j)
          lattice[j] = grid.lattice_cell_of_local_cell(cells[j]);
        return lattice;
      }

      void sum_nodal(double *values, const int count) override
      {
        timed([&] { grid.sum_packed_nodes(values, count); });
      }
      void sum_nodal(float *values, const int count) override
      {
        timed([&] { grid.sum_packed_nodes(values, count); });
      }

      void sum_cells(double *values, const int count) override
      {
        timed([&] { grid.sum_packed_cells(values, count); });
      }
      void sum_cells(float *values, const int count) override
      {
        timed([&] { grid.sum_packed_cells(values, count); });
      }

      // The host's part of the exchanges so far: the copies of the owned entries and the
      // partitioner's MPI.
      double host_seconds() const { return seconds; }

    private:
      const BackgroundGrid<dim>       &grid;
      const std::vector<unsigned int> nodes, cells;
      double                          seconds = 0;

      template <typename Work>
      void timed(Work &&work)
      {
        const auto start = std::chrono::steady_clock::now();
        work();
        seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      }
    };

    // Real: the type the device keeps the points and nodes in (float: Backend/Precision =
    // float); the interface, and the points that change rank, stay in double.
    template <int dim, typename Real = double>
    class CudaEngine : public Engine<dim>
    {
    public:
      // One rank: the device keeps the lattice's nodes, no ghost nodes, no exchange; with
      // active_block_cells > 0 only those near the points (keep_nodes_near_points), chosen
      // when points are loaded and by refresh_active_nodes(), the device starting with none.
      CudaEngine(HostGrid<dim, double> lattice, const std::vector<MaterialParameters<double>> &materials,
                 const ShapeFunction shape, const int active_block_cells)
        : materials(materials)
        , shape(shape)
      {
        for (int d = 0; d < dim; ++d)
          lattice_origin[d] = lattice.origin[d];
        lattice_h                  = lattice.h;
        GridView<dim, double> view = make_grid_view<dim, double>(lattice);
        if (active_block_cells > 0) // no node until the points are loaded
          {
            this->near_material.block_cells              = active_block_cells;
            this->near_material.shape                    = shape;
            faces = lattice.faces;
            for (int f = 0; f < 2 * dim; ++f) // (the view has them only with a mask array)
              view.friction_coefficient[f] = lattice.friction_coefficient[f];
            view.lattice_to_node     = nullptr;
            view.n_nodes             = 0; // (the friction coefficients are taken, the masks later)
            for (int d = 0; d < dim; ++d)
              view.box_nodes[d] = 0;
          }
        device = std::make_unique<cuda::DeviceEngine<dim, Real>>(view, materials, shape, nullptr);
      }

      void refresh_active_nodes() override
      {
        auto &near = this->near_material;
        if (this->follows_material())
          {
            const int n_kept = choose_nodes_near_material(
              near.block_cells, [&]() { return device->keep_nodes_near_points(near.block_cells, faces); });
            near.kept(n_kept, device->kept_nodes_are_box()); // asked after the choice
          }
      }

      void cells_with_mass(typename GridSnapshot<dim>::LatticeCells &out) override
      {
        AssertThrow(this->follows_material(),
                    dealii::ExcMessage("Internal: cells_with_mass() needs Nodes = near material."));
        HostGrid<dim, double> nodes;
        std::vector<long>     lattice_of_node;
        const GridView<dim, double> view = device->download_kept_nodes(nodes, lattice_of_node);
        out = lattice_cells_with_mass(view, lattice_of_node, lattice_origin, lattice_h);
      }

      // Several ranks: the device keeps this rank's locally relevant nodes, numbered as the
      // grid's vectors, and sums them over the ranks through the grid's partitioner.
      CudaEngine(BackgroundGrid<dim> &grid, const std::vector<MaterialParameters<double>> &materials,
                 const ShapeFunction shape)
        : shared_grid(&grid)
        , materials(materials)
        , shape(shape)
      {
        build_on_grid();
      }

      void load(const MaterialPoints<dim> &p) override
      {
        // A repartition renumbered the nodes: the device's grid and exchange follow.
        if (shared_grid != nullptr && shared_grid->partitioner != built_for)
          build_on_grid();
        auto new_labels = std::make_shared<PointLabels<dim>>();
        p.copy_to(host, shared_grid != nullptr ? &home_cells : nullptr, new_labels.get());
        load(host, std::move(new_labels));
        if (shared_grid != nullptr)
          device->set_home_cells(home_cells);
        handler_behind = false;
      }

      // The re-sort on the device: only the points that now lie in another rank's cell
      // come down, travel (deal.II's some_to_some, to the owner of their ghost cell) and go
      // up on their new rank, with their labels; the labels of the points that stay never
      // leave the device. The handler is left behind until sync().
      unsigned int resort(MaterialPoints<dim> &p) override
      {
        if (shared_grid == nullptr)
          return store(p);
        HostPoints<dim, double>          leaving;
        std::vector<std::vector<double>> leaving_labels;
        const int                        dropped = device->take_leaving_points(leaving, leaving_labels);

        const unsigned int this_rank = dealii::Utilities::MPI::this_mpi_process(shared_grid->communicator);
        const int          n_values  = values_per_point(leaving);
        const int          n_labels  = static_cast<int>(leaving_labels.size());
        std::map<unsigned int, std::vector<double>> outgoing;
        for (int k = 0; k < leaving.size(); ++k)
          {
            double x[dim];
            for (int d = 0; d < dim; ++d)
              x[d] = leaving.position[d][k];
            const int owner = owner_of_cell[shared_grid->lattice_cell_of(x)];
            AssertThrow(owner >= 0 && owner != static_cast<int>(this_rank),
                        dealii::ExcMessage("Internal: a point moved beyond the ghost cells of its rank between "
                                           "two re-sorts (Parallel/Re-sort distance)."));
            std::vector<double> &to = outgoing[owner];
            for_each_point_array<dim>(leaving, leaving, [&](const auto &array, const auto &) {
              to.push_back(static_cast<double>(array[k]));
            });
            for (int l = 0; l < n_labels; ++l)
              to.push_back(leaving_labels[l][k]);
          }
        const std::map<unsigned int, std::vector<double>> incoming =
          dealii::Utilities::MPI::some_to_some(shared_grid->communicator, outgoing);

        // Appended in the order of the senders' ranks.
        int n_received = 0;
        for (const auto &from : incoming)
          n_received += static_cast<int>(from.second.size()) / (n_values + n_labels);
        HostPoints<dim, double> received;
        received.fields = leaving.fields;
        received.set_n_state_variables(leaving.n_state_variables());
        received.resize(n_received);
        std::vector<std::vector<double>> received_labels(n_labels, std::vector<double>(n_received));
        int k = 0;
        for (const auto &from : incoming)
          for (std::size_t at = 0; at < from.second.size(); ++k)
            {
              for_each_point_array<dim>(received, received, [&](auto &array, auto &) {
                using T  = typename std::decay_t<decltype(array)>::value_type;
                array[k] = static_cast<T>(from.second[at++]);
              });
              for (int l = 0; l < n_labels; ++l)
                received_labels[l][k] = from.second[at++];
            }
        device->append_points(received, received_labels);
        labels_on_device_only = true;
        p.n_sent += leaving.size();
        handler_behind = true;
        return static_cast<unsigned int>(dropped);
      }

      // The handler gets the device's points (each rank's are in its own cells), and the
      // device takes them back in the handler's order.
      void sync(MaterialPoints<dim> &p) override
      {
        if (!handler_behind)
          return;
        PointSnapshot<dim> now;
        snapshot(now);
        p.replace(now);
        load(p);
      }

      long n_points() const override { return device->n_points(); }

      double exchange_seconds() override
      {
        return shared_grid == nullptr ? -1 : exchange_seconds_before + device->exchange_seconds();
      }

      double share_of_points_before_overlap() override
      {
        return shared_grid == nullptr ? -1 : device->share_of_points_before_overlap();
      }

      double exchange_host_seconds() override
      {
        return shared_grid == nullptr ? -1 : exchange_host_seconds_before + exchange->host_seconds();
      }

      void load(const HostPoints<dim, double> &p, std::shared_ptr<const PointLabels<dim>> new_labels) override
      {
        labels = std::move(new_labels); // a snapshot being written keeps the old ones
        device->upload_points(p);
        labels_on_device_only = false;
        if (shared_grid == nullptr)
          return refresh_active_nodes();
        // Several ranks: the labels travel with the points at re-sorts, on the device.
        std::vector<std::vector<double>> arrays(1 + dim);
        arrays[0].assign(labels->id.begin(), labels->id.end());
        for (int d = 0; d < dim; ++d)
          arrays[1 + d] = labels->initial_position[d];
        device->upload_labels(arrays);
      }

      // Hand-over to the handler (an MPI re-sort): points come back, points that left the
      // grid are removed, the handler's new order goes back down.
      unsigned int store(MaterialPoints<dim> &p) override
      {
        host.resize(device->n_points());
        device->download_points(host);
        const unsigned int removed = p.copy_from(host);
        load(p);
        return removed;
      }

      // Output: the points come down in the order of the last upload (DeviceEngine's
      // contract), which is the labels' order.
      void snapshot(PointSnapshot<dim> &s) override
      {
        s.wait_for_points(); // nothing left to overwrite these points later
        s.points.resize(device->n_points());
        device->download_points(s.points);
        take_labels(s);
      }

      // The points come down while the steps go on (DeviceEngine::begin_download_points);
      // s.wait_for_points() finishes it. MPM_OUTPUT_OVERLAP=0 waits here instead (for measuring).
      void start_snapshot(PointSnapshot<dim> &s) override
      {
        static const bool overlap = [] {
          const char *v = std::getenv("MPM_OUTPUT_OVERLAP");
          return !(v != nullptr && v[0] == '0');
        }();
        if (!overlap)
          return snapshot(s);
        s.wait_for_points(); // an earlier download nobody read
        s.arrival = device->begin_download_points(s.points);
        take_labels(s);
      }

      // The labels of the points as they come down.
      void take_labels(PointSnapshot<dim> &s)
      {
        if (labels_on_device_only)
          {
            // Re-sorts moved the labels on the device: they come down in upload order.
            std::vector<std::vector<double>> arrays;
            device->download_labels(arrays);
            auto now                  = std::make_shared<PointLabels<dim>>();
            now->state_variable_names = labels->state_variable_names;
            now->id.assign(arrays[0].begin(), arrays[0].end()); // ids below 2^53 are exact in a double
            for (int d = 0; d < dim; ++d)
              now->initial_position[d] = std::move(arrays[1 + d]);
            labels                = std::move(now); // a snapshot being written keeps the old ones
            labels_on_device_only = false;
          }
        s.labels = labels;
      }

      // The device's nodes into the grid's numbering.
      void nodal_to(BackgroundGrid<dim> &grid) override { device->download_nodal(grid.view()); }

      StepReduction<double> step(const StepSettings<dim, double> &s, const double dt) override
      {
        return device->step(s, dt);
      }

      bool queues_steps() const override { return shared_grid == nullptr; } // one rank

      void queue_step(const StepSettings<dim, double> &s, const TimeStepRule &rule, const double time,
                      const double next_output, const bool speed_from_host, const double host_speed) override
      {
        device->queue_step(s, rule, time, next_output, speed_from_host, host_speed);
      }

      QueuedStep collect_step() override { return device->collect_step(); }

      PointTotals<dim, double> totals() override { return device->totals(); }

      double relative_mass_round_off() const override { return relative_mass_round_off_of<Real>(); }

      double max_distance_outside_home_cells() override
      {
        AssertThrow(shared_grid != nullptr || this->follows_material(),
                    dealii::ExcMessage("Internal: the home cells are known only for points loaded from the "
                                       "ParticleHandler or where the nodes follow the points."));
        return device->max_distance_outside_home_cells();
      }

      void set_materials(const std::vector<MaterialParameters<double>> &m) override
      {
        materials = m;
        device->set_materials(m);
      }

      void set_sort_interval(const int steps) override
      {
        sort_interval = steps;
        device->set_sort_interval(steps);
      }

    private:
      BackgroundGrid<dim>                    *shared_grid = nullptr;
      std::vector<MaterialParameters<double>> materials; // the latest table, for a rebuild
      FaceConditions<dim>                     faces; // one rank near the material: the kept nodes' masks
      double lattice_origin[dim] = {}, lattice_h = 0; // one rank: the lattice's geometry in double (output)
      ShapeFunction                           shape;
      int                                     sort_interval = -1; // -1: the device's default
      // The partition the device's nodes were built for (kept alive, so a new one cannot
      // reuse its address).
      std::shared_ptr<const dealii::Utilities::MPI::Partitioner> built_for;
      double exchange_seconds_before = 0, exchange_host_seconds_before = 0; // on devices since rebuilt
      std::unique_ptr<GridExchange<dim>>      exchange; // declared before device: outlives it
      std::unique_ptr<cuda::DeviceEngine<dim, Real>> device;
      HostPoints<dim, double>                 host;       // staging for load/store from the handler only
      std::vector<long>                       home_cells; // several ranks: lattice cell of each point at load
      std::shared_ptr<const PointLabels<dim>> labels;     // id, initial position, in the uploaded order
      // Several ranks: a re-sort has changed the points since `labels` was made; the device's
      // labels are the current ones.
      bool labels_on_device_only = false;
      // Several ranks: the owner of each owned or ghost lattice cell (-1 elsewhere), and
      // whether resort() has moved points since the handler last saw them.
      std::vector<int> owner_of_cell;
      bool             handler_behind = false;

      static int values_per_point(HostPoints<dim, double> &points)
      {
        int n = 0;
        for_each_point_array<dim>(points, points, [&](const auto &, const auto &) { ++n; });
        return n;
      }

      void build_on_grid()
      {
        if (device != nullptr)
          {
            exchange_seconds_before += device->exchange_seconds();
            exchange_host_seconds_before += exchange->host_seconds();
          }
        device.reset();
        exchange  = std::make_unique<GridExchange<dim>>(*shared_grid);
        built_for = shared_grid->partitioner;
        device    = std::make_unique<cuda::DeviceEngine<dim, Real>>(shared_grid->view(), materials, shape, exchange.get());
        if (sort_interval >= 0)
          device->set_sort_interval(sort_interval);
        long n_lattice_cells = 1;
        for (int d = 0; d < dim; ++d)
          n_lattice_cells *= shared_grid->n_cells[d];
        owner_of_cell.assign(n_lattice_cells, -1);
        std::vector<std::uint8_t> owned(n_lattice_cells, 0);
        for (const auto &cell : shared_grid->triangulation.active_cell_iterators())
          if (cell->is_locally_owned() || cell->is_ghost())
            shared_grid->for_each_lattice_cell(cell, [&](const long c) {
              owner_of_cell[c] = static_cast<int>(cell->subdomain_id());
              owned[c]         = cell->is_locally_owned() ? 1 : 0;
            });
        device->set_owned_cells(owned);
      }
    };

    // The rank's place on its node: ranks of one node share its GPUs.
    int node_local_rank(const MPI_Comm communicator)
    {
      MPI_Comm node;
      MPI_Comm_split_type(communicator, MPI_COMM_TYPE_SHARED, 0, MPI_INFO_NULL, &node);
      int rank = 0;
      MPI_Comm_rank(node, &rank);
      MPI_Comm_free(&node);
      return rank;
    }

    bool mpi_is_cuda_aware()
    {
#  if defined(MPIX_CUDA_AWARE_SUPPORT) && MPIX_CUDA_AWARE_SUPPORT
      return MPIX_Query_cuda_support() == 1;
#  else
      return false;
#  endif
    }

    // Every rank's check for a usable device, refused on all ranks together.
    void check_device(const MPI_Comm communicator)
    {
      std::string why;
      const bool  usable = cuda::device_count(&why) > 0;
      const bool  all    = dealii::Utilities::MPI::min(usable ? 1 : 0, communicator) == 1;
      AssertThrow(usable, dealii::ExcMessage("Parameter 'Backend/Backend': 'cuda' was asked for, but no CUDA device "
                                             "is usable (" + why + "). Use 'cpu', or run on a machine with an "
                                             "NVIDIA GPU and driver."));
      AssertThrow(all, dealii::ExcMessage("Parameter 'Backend/Backend': 'cuda' was asked for, but another MPI rank "
                                          "found no usable CUDA device (its message says why)."));
    }

    void check_models(const std::vector<MaterialParameters<double>> &materials)
    {
      for (const MaterialParameters<double> &m : materials)
        AssertThrow(m.model != MaterialModel::user_defined,
                    dealii::ExcMessage("Parameter 'Backend/Backend': 'cuda' cannot run a constitutive model defined "
                                       "outside the library (UserConstitutiveModel); use 'cpu'."));
    }
  } // namespace
#endif

#ifndef MPM_CUDA_ENGINE
  namespace
  {
    dealii::ExcMessage not_built()
    {
      return dealii::ExcMessage("Parameter 'Backend/Backend': 'cuda' is not available in this build (allowed here: "
                                "cpu). Configure with -DMPM_WITH_CUDA=ON (needs nvcc) for cuda.");
    }
  } // namespace
#endif

  bool cuda_engine_built()
  {
#ifdef MPM_CUDA_ENGINE
    return true;
#else
    return false;
#endif
  }

  std::future<void> start_cuda_initialisation(const MPI_Comm communicator)
  {
#ifdef MPM_CUDA_ENGINE
    const int local_rank = node_local_rank(communicator);
    return std::async(std::launch::async, [local_rank] {
      cuda::use_device_of_local_rank(local_rank);
      cuda::initialise_device();
    });
#else
    (void)communicator;
    std::promise<void> nothing_to_do;
    nothing_to_do.set_value();
    return nothing_to_do.get_future();
#endif
  }

  template <int dim>
  std::unique_ptr<Engine<dim>> make_cuda_engine(const HostGrid<dim, double> &lattice,
                                                const std::vector<MaterialParameters<double>> &materials,
                                                const ShapeFunction shape, const int active_block_cells,
                                                const bool single_precision)
  {
#ifdef MPM_CUDA_ENGINE
    check_models(materials);
    check_device(MPI_COMM_SELF);
    cuda::use_device_of_local_rank(0);
    std::cout << "  CUDA device: " << cuda::device_description() << std::endl; // one rank
    if (single_precision)
      return std::make_unique<CudaEngine<dim, float>>(lattice, materials, shape, active_block_cells);
    return std::make_unique<CudaEngine<dim>>(lattice, materials, shape, active_block_cells);
#else
    (void)single_precision;
    (void)active_block_cells;
    (void)lattice;
    (void)materials;
    (void)shape;
    AssertThrow(false, not_built());
    return nullptr;
#endif
  }

  template <int dim>
  std::unique_ptr<Engine<dim>> make_cuda_engine(BackgroundGrid<dim> &grid,
                                                const std::vector<MaterialParameters<double>> &materials,
                                                const ShapeFunction shape, const bool single_precision)
  {
#ifdef MPM_CUDA_ENGINE
    check_models(materials);
    check_device(grid.communicator);
    const int device = cuda::use_device_of_local_rank(node_local_rank(grid.communicator));
    // One line per rank, printed by rank 0: which GPU each rank drives, and how the
    // ghost exchange travels.
    const std::vector<std::string> devices = dealii::Utilities::MPI::gather(
      grid.communicator, "GPU " + std::to_string(device) + ", " + cuda::device_description(), 0);
    const std::size_t staged = grid.exchanged_local_nodes().size() * (single_precision ? sizeof(float) : sizeof(double));
    const std::vector<std::size_t> bytes = dealii::Utilities::MPI::gather(grid.communicator, staged, 0);
    if (dealii::Utilities::MPI::this_mpi_process(grid.communicator) == 0)
      {
        for (std::size_t r = 0; r < devices.size(); ++r)
          std::cout << "  CUDA device of rank " << r << ": " << devices[r] << std::endl;
        std::cout << "  ghost-node exchange staged through pinned host memory ("
                  << (mpi_is_cuda_aware() ? "the MPI is CUDA-aware, but device buffers are not passed to it yet" :
                                            "the MPI is not CUDA-aware")
                  << "): " << *std::max_element(bytes.begin(), bytes.end())
                  << " bytes per array each way on the busiest rank, at the start; "
                  << (cuda::exchange_overlap_enabled() ? "overlapped with the passes of the points that cannot reach it" :
                                          "not overlapped (MPM_CUDA_OVERLAP=0)")
                  << std::endl;
        if (single_precision)
          std::cout << "  float on several GPU ranks: the nodal and cell sums exchanged in float" << std::endl;
      }
    if (single_precision)
      return std::make_unique<CudaEngine<dim, float>>(grid, materials, shape);
    return std::make_unique<CudaEngine<dim>>(grid, materials, shape);
#else
    (void)single_precision;
    (void)grid;
    (void)materials;
    (void)shape;
    AssertThrow(false, not_built());
    return nullptr;
#endif
  }

  template std::unique_ptr<Engine<2>> make_cuda_engine(const HostGrid<2, double> &,
                                                       const std::vector<MaterialParameters<double>> &, ShapeFunction,
                                                       int, bool);
  template std::unique_ptr<Engine<3>> make_cuda_engine(const HostGrid<3, double> &,
                                                       const std::vector<MaterialParameters<double>> &, ShapeFunction,
                                                       int, bool);
  template std::unique_ptr<Engine<2>> make_cuda_engine(BackgroundGrid<2> &,
                                                       const std::vector<MaterialParameters<double>> &, ShapeFunction,
                                                       bool);
  template std::unique_ptr<Engine<3>> make_cuda_engine(BackgroundGrid<3> &,
                                                       const std::vector<MaterialParameters<double>> &, ShapeFunction,
                                                       bool);
} // namespace mpm
