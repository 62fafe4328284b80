// mpm::cuda::DeviceEngine (include/mpm/cuda/device_engine.h): set-up, the points' and the
// grid's transfers between host and device, materials, labels and totals. The step is in
// queued_steps.cu and run_step.cuh, migration in migration.cu, the nodes near the material
// in kept_nodes.cu. The explicit instantiation here covers the members defined in this file.
#include "engine_state.cuh"

namespace mpm
{
  namespace cuda
  {
    template <int dim, typename Real>
    DeviceEngine<dim, Real>::DeviceEngine(const GridView<dim, double> &g,
                                    const std::vector<MaterialParameters<double>> &materials, const ShapeFunction shape,
                                    NodalExchange *exchange)
    {
      std::string why;
      if (device_count(&why) == 0)
        throw std::runtime_error("no CUDA device: " + why);
      impl        = std::make_unique<Impl>();
      impl->shape = shape;
      if (const char *from = std::getenv("MPM_CUDA_KERNEL_TIMES"))
        impl->timed_from = std::atol(from);
      // MPM_CUDA_GRAPHS=0: queued steps launched one kernel at a time (for measuring);
      // MPM_CUDA_SYNC=1 synchronises after each launch, which a capture cannot.
      const char *graphs = std::getenv("MPM_CUDA_GRAPHS");
      const char *sync   = std::getenv("MPM_CUDA_SYNC");
      impl->graphs.enabled = !(graphs != nullptr && graphs[0] == '0') && !(sync != nullptr && sync[0] == '1');
      // The host grid description: geometry, lookup and masks, nodal arrays zeroed.
      HostGrid<dim, double> host;
      host.h   = g.h;
      impl->host_lattice.h = g.h;
      long n_lattice_nodes = 1;
      for (int d = 0; d < dim; ++d)
        {
          host.origin[d]  = g.origin[d];
          host.n_cells[d] = g.n_cells[d];
          impl->host_lattice.origin[d]  = g.origin[d];
          impl->host_lattice.n_cells[d] = g.n_cells[d];
          n_lattice_nodes *= g.n_cells[d] + 1;
          impl->n_lattice_cells *= g.n_cells[d];
        }
      // The device numbers its nodes in lattice order (x fastest; deal.II numbers its DoFs
      // cell by cell), so that its grid view needs no lookup and the atomics of neighbouring
      // points hit neighbouring addresses (DeviceGrid::lattice_order; 6% off P1's step on
      // one rank). It keeps the slab of whole lattice layers, along the last direction,
      // that holds every host node: the lattice on one rank, the rank's part and its ghost
      // layers on several (a slab node the host does not hold stays massless: no point of
      // the rank reaches it). download_nodal and the exchange translate to the host's
      // numbering.
      const long       layer = n_lattice_nodes / (g.n_cells[dim - 1] + 1);
      // No host node (the nodes near the material come later): no pass over the lattice.
      std::vector<int> lattice_nodes(g.n_nodes > 0 ? n_lattice_nodes : 0);
      for (long l = 0; l < static_cast<long>(lattice_nodes.size()); ++l)
        lattice_nodes[l] = g.node_of_lattice(l);
      long             first = -1, last = -1;
      std::vector<long> lattice_of_host(g.n_nodes, -1);
      for (long l = 0; l < static_cast<long>(lattice_nodes.size()); ++l)
        if (const int node = lattice_nodes[l]; node >= 0)
          {
            if (node >= g.n_nodes || lattice_of_host[node] >= 0)
              throw std::invalid_argument("DeviceEngine: the host grid's lattice lookup is not one to one");
            lattice_of_host[node] = l;
            first                 = first < 0 ? l : first;
            last                  = l;
          }
      const long node_offset = first < 0 ? 0 : first / layer * layer;
      const long n_slab      = first < 0 ? 0 : (last / layer + 1) * layer - node_offset;
      if (n_slab > std::numeric_limits<int>::max())
        throw std::invalid_argument("DeviceEngine: more lattice nodes in the rank's slab than an int can count");
      impl->slab_of_host.resize(g.n_nodes);
      for (int node = 0; node < g.n_nodes; ++node)
        impl->slab_of_host[node] = lattice_of_host[node] < 0 ? -1 : static_cast<int>(lattice_of_host[node] - node_offset);
      host.allocate_nodes(static_cast<int>(n_slab));
      host.fixed_components.assign(n_slab, 0);
      for (long b = 0; b < n_slab; ++b)
        if (const int node = lattice_nodes[node_offset + b]; node >= 0)
          host.fixed_components[b] = g.fixed_components[node];
      for (int f = 0; f < 2 * dim; ++f) // also where the masks come later (near the material)
        host.friction_coefficient[f] = g.friction_coefficient[f];
      if (g.friction_faces != nullptr)
        {
          host.friction_faces.assign(n_slab, 0);
          for (long b = 0; b < n_slab; ++b)
            if (const int node = lattice_nodes[node_offset + b]; node >= 0)
              host.friction_faces[b] = g.friction_faces[node];
        }
      impl->grid.upload(converted<Real>(host));
      int slab_lower[dim], slab_nodes[dim]; // no lookup: the slab's layers, lattice order
      for (int d = 0; d < dim; ++d)
        {
          slab_lower[d] = d < dim - 1 ? 0 : static_cast<int>(node_offset / layer);
          slab_nodes[d] = d < dim - 1 ? g.n_cells[d] + 1 : static_cast<int>(n_slab / layer);
        }
      impl->grid.set_box(slab_lower, slab_nodes);
      impl->materials.upload(converted<Real>(materials));
      impl->all_laws    = materials_need_all_physics(materials);
      impl->disconnects = disconnects_points(materials);
      impl->exchange = ExchangeAdapter<Real>{exchange, &impl->backend, &impl->exchanged_nodes, &impl->exchanged_cells};
      if (exchange != nullptr)
        {
          std::vector<int> slab_nodes = exchange->exchanged_nodes();
          for (int &node : slab_nodes)
            {
              node = node >= 0 && node < g.n_nodes ? impl->slab_of_host[node] : -1;
              if (node < 0)
                throw std::invalid_argument("DeviceEngine: an exchanged node is not in the host grid's lattice");
            }
          impl->exchanged_nodes.set_index(slab_nodes);
          impl->exchanged_cells.set_index(exchange->exchanged_cells());
          if (exchange_overlap_enabled())
            {
              std::vector<long> lattice_nodes_exchanged(slab_nodes.size());
              for (std::size_t j = 0; j < slab_nodes.size(); ++j)
                lattice_nodes_exchanged[j] = slab_nodes[j] + node_offset;
              impl->cells_before_overlap.upload(
                cells_reaching_exchange<dim>(g.n_cells, lattice_nodes_exchanged, exchange->exchanged_cells()));
            }
        }
    }

    template <int dim, typename Real>
    DeviceEngine<dim, Real>::~DeviceEngine() = default;

    template <int dim, typename Real>
    void DeviceEngine<dim, Real>::upload_points(const HostPoints<dim, double> &p)
    {
      if constexpr (std::is_same<Real, double>::value)
        impl->points.upload(p);
      else
        {
          HostPoints<dim, Real> rounded;
          convert_points<Real>(p, rounded);
          impl->points.upload(rounded);
        }
      impl->order.reset(impl->backend, impl->points.size());
      impl->home_cells.resize(0); // set_home_cells gives those of these points
      impl->home_by_slot_stale = true;
      impl->labels.clear();       // upload_labels gives those of these points
      impl->steps_since_upload = 0;
      impl->exchange.first_points = -1; // until the next sort, by these points' home cells
      impl->averaging_pending  = false; // the host's stresses are final
    }

    template <int dim, typename Real>
    void DeviceEngine<dim, Real>::download_points(HostPoints<dim, double> &p) const
    {
      impl->finish_pending_averaging();
      impl->backend.synchronize();
      if constexpr (std::is_same<Real, double>::value)
        impl->order.download_in_reference_order(impl->backend, impl->points, p);
      else
        {
          HostPoints<dim, Real> rounded;
          impl->order.download_in_reference_order(impl->backend, impl->points, rounded);
          convert_points<double>(rounded, p);
        }
    }

    template <int dim, typename Real>
    std::function<void()> DeviceEngine<dim, Real>::begin_download_points(HostPoints<dim, double> &p)
    {
      if (!impl->output_download)
        impl->output_download = std::make_shared<OutputDownload<Real>>();
      const std::shared_ptr<OutputDownload<Real>> download = impl->output_download;
      if (download->unfinished)
        throw std::logic_error("DeviceEngine::begin_download_points: the last download was not finished (call the "
                               "function it returned first)");
      impl->finish_pending_averaging();
      const DevicePoints<dim, Real> &points = impl->points;
      const int                      n      = points.size();
      p.fields = points.fields;
      p.resize(n);
      if (p.n_state_variables() < points.n_state_variables())
        p.set_n_state_variables(points.n_state_variables());
      // Where each array lands on the host, in the order the copies fill the pinned memory.
      std::vector<double *> real_to;
      std::vector<int *>    int_to;
      for_each_point_array<dim>(points, p, [&](const auto &device, auto &host) {
        using T = typename std::decay_t<decltype(device)>::value_type;
        if constexpr (std::is_same<T, int>::value)
          int_to.push_back(host.data());
        else
          real_to.push_back(host.data());
      });
      download->reserve(real_to.size() * std::size_t(n), int_to.size() * std::size_t(n));
      impl->order.queue_download_in_reference_order(impl->backend, points, download->reals, download->ints);
      MPM_CUDA_CHECK(cudaEventRecord(download->copied, impl->backend.get_stream()));
      download->unfinished = true;
      return [download, n, real_to = std::move(real_to), int_to = std::move(int_to)]() {
        MPM_CUDA_CHECK(cudaEventSynchronize(download->copied));
        for (std::size_t k = 0; k < real_to.size(); ++k)
          std::copy(download->reals + k * n, download->reals + (k + 1) * n, real_to[k]); // float: to double
        for (std::size_t k = 0; k < int_to.size(); ++k)
          std::copy(download->ints + k * n, download->ints + (k + 1) * n, int_to[k]);
        download->unfinished = false;
      };
    }

    template <int dim, typename Real>
    void DeviceEngine<dim, Real>::set_sort_interval(const int steps)
    {
      if (steps < 0)
        throw std::invalid_argument("DeviceEngine::set_sort_interval: the interval must be >= 0");
      sort_interval = steps;
    }

    template <int dim, typename Real>
    void DeviceEngine<dim, Real>::download_nodal(const GridView<dim, double> &g) const
    {
      impl->backend.synchronize();
      const DeviceGrid<dim, Real> &dg = impl->grid;
      for (int d = 0; d < dim; ++d)
        if (g.n_cells[d] != dg.n_cells[d])
          throw std::invalid_argument("DeviceEngine::download_nodal: the host grid has another lattice");
      // Device node b is the host's node of its lattice index (absent from the host: not
      // written).
      std::vector<Real>   staging(dg.mass.size());
      std::vector<int>    host_node(staging.size());
      for (size_t b = 0; b < host_node.size(); ++b)
        {
          const long lattice = impl->lattice_of_device_node(static_cast<long>(b));
          host_node[b]       = lattice < 0 ? -1 : g.node_of_lattice(lattice);
        }
      auto download = [&](double *to, const DeviceArray<Real> &from) {
        from.download(staging);
        for (size_t b = 0; b < staging.size(); ++b)
          if (host_node[b] >= 0)
            to[host_node[b]] = staging[b];
      };
      // Mass and velocity only: the nodal fields that the output writes (a quarter of the
      // bytes of all four arrays; after the step, force[] holds G2P's blended vector).
      download(g.mass, dg.mass);
      for (int d = 0; d < dim; ++d)
        download(g.velocity[d], dg.velocity[d]);
    }

    template <int dim, typename Real>
    PointTotals<dim, double> DeviceEngine<dim, Real>::totals()
    {
      // Summed in double whatever Real is (the loss checks compare the mass with its first sum).
      return point_totals<dim, Real, CudaBackend, double>(impl->backend, impl->points.view());
    }

    template <int dim, typename Real>
    void DeviceEngine<dim, Real>::set_materials(const std::vector<MaterialParameters<double>> &materials)
    {
      impl->backend.synchronize(); // the table may be in use by a launch in flight
      impl->materials.upload(converted<Real>(materials));
      impl->all_laws    = materials_need_all_physics(materials);
      impl->disconnects = disconnects_points(materials);
    }

    template <int dim, typename Real>
    void DeviceEngine<dim, Real>::upload_labels(const std::vector<std::vector<double>> &labels)
    {
      impl->labels.resize(labels.size());
      for (std::size_t k = 0; k < labels.size(); ++k)
        {
          if (static_cast<int>(labels[k].size()) != impl->points.size())
            throw std::invalid_argument("DeviceEngine::upload_labels: one label per uploaded point is needed");
          impl->labels[k].upload(labels[k]);
        }
    }

    template <int dim, typename Real>
    void DeviceEngine<dim, Real>::download_labels(std::vector<std::vector<double>> &labels) const
    {
      impl->backend.synchronize();
      labels.resize(impl->labels.size());
      for (std::size_t k = 0; k < labels.size(); ++k)
        impl->labels[k].download(labels[k]);
    }

    template <int dim, typename Real>
    double DeviceEngine<dim, Real>::exchange_seconds()
    {
      return impl->exchanged_nodes.exchange_seconds() + impl->exchanged_cells.exchange_seconds();
    }

    template <int dim, typename Real>
    double DeviceEngine<dim, Real>::share_of_points_before_overlap() const
    {
      return impl->n_split_sorts > 0 ? impl->first_share_sum / impl->n_split_sorts : -1;
    }

    template <int dim, typename Real>
    int DeviceEngine<dim, Real>::n_points() const
    {
      return impl->points.size();
    }

    template class DeviceEngine<2, double>;
    template class DeviceEngine<3, double>;
    template class DeviceEngine<2, float>;
    template class DeviceEngine<3, float>;
  } // namespace cuda
} // namespace mpm
