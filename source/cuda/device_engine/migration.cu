// mpm::cuda::DeviceEngine's side of the migration between ranks: the points' home cells and
// how far they have left them, the owned cells, the points that leave (taken out of the
// device's arrays) and those that arrive (appended).
#include "engine_state.cuh"

namespace mpm
{
  namespace cuda
  {
    template <int dim, typename Real>
    void DeviceEngine<dim, Real>::set_home_cells(const std::vector<long> &home_cells)
    {
      if (static_cast<int>(home_cells.size()) != impl->points.size())
        throw std::invalid_argument("DeviceEngine::set_home_cells: one home cell per uploaded point is needed");
      impl->home_cells.upload(home_cells);
      impl->home_by_slot_stale    = true;
      impl->exchange.first_points = -1; // the split follows the home cells at the next sort
    }

    template <int dim, typename Real>
    double DeviceEngine<dim, Real>::max_distance_outside_home_cells()
    {
      const int n = impl->points.size();
      if (static_cast<int>(impl->home_cells.size()) != n)
        throw std::logic_error("DeviceEngine: the home cells of the uploaded points are not known");
      if (impl->home_by_slot_stale)
        {
          // Once per order (a stencil sort every sort_interval steps), not per step: the
          // gather through the permutation is a random read per point.
          impl->home_by_slot.resize(n);
          const long *home     = impl->home_cells.data();
          const int  *original = impl->order.original_index(); // slot -> upload order
          long       *to       = impl->home_by_slot.data();
          if (n > 0)
            impl->backend.for_each_node(n, [=] MPM_HOST_DEVICE(const int i) { to[i] = home[original[i]]; });
          impl->home_by_slot_stale = false;
        }
      const PointsView<dim, Real> p    = impl->points.view();
      const GridView<dim, Real>   g    = impl->grid.view();
      const long                 *home = impl->home_by_slot.data();
      return impl->backend.reduce_points(
        n, 0.0,
        [=] MPM_HOST_DEVICE(const int i) {
          const Real out = distance_outside_home_cell<dim>(g.origin, g.h, g.n_cells, p.position, home[i], i);
          return p.material[i] < 0 ? 0.0 : static_cast<double>(out);
        },
        [] MPM_HOST_DEVICE(const double a, const double b) { return a > b ? a : b; });
    }

    template <int dim, typename Real>
    void DeviceEngine<dim, Real>::set_owned_cells(const std::vector<std::uint8_t> &owned)
    {
      if (static_cast<long>(owned.size()) != impl->n_lattice_cells)
        throw std::invalid_argument("DeviceEngine::set_owned_cells: one entry per lattice cell is needed");
      impl->owned_cells.upload(owned);
    }

    template <int dim, typename Real>
    int DeviceEngine<dim, Real>::take_leaving_points(HostPoints<dim, double>          &leaving,
                                               std::vector<std::vector<double>> &leaving_labels)
    {
      if (static_cast<long>(impl->owned_cells.size()) != impl->n_lattice_cells)
        throw std::logic_error("DeviceEngine::take_leaving_points: the owned cells are not known");
      impl->finish_pending_averaging();
      const int n = impl->points.size();
      // Per slot: stays, leaves for another rank, or left the grid. The slots of the first
      // two kinds are listed on the device (CUB's flagged select, in slot order); only the
      // lists' upload-order indices and the leaving points come down.
      ResortScratch              &r       = impl->resort;
      const PointsView<dim, Real> p       = impl->points.view();
      const HostLattice<dim>      lattice = impl->host_lattice;
      const std::uint8_t         *owned   = impl->owned_cells.data();
      r.keep_flag.resize(n);
      r.leave_flag.resize(n);
      r.slot.resize(n);
      std::uint8_t *keep = r.keep_flag.data(), *leave = r.leave_flag.data();
      int          *slot = r.slot.data();
      impl->backend.for_each_node(n, [=] MPM_HOST_DEVICE(const int i) {
        slot[i] = i;
        if (p.material[i] < 0)
          {
            keep[i] = leave[i] = 0;
            return;
          }
        const bool mine = owned[lattice.cell_of(p.position, i)] != 0;
        keep[i]         = mine ? 1 : 0;
        leave[i]        = mine ? 0 : 1;
      });
      const cudaStream_t stream = impl->backend.get_stream();
      r.kept_slots.resize(n);
      r.leaving_slots.resize(n);
      r.counts.resize(2);
      size_t bytes = 0;
      MPM_CUDA_CHECK(cub::DeviceSelect::Flagged(nullptr, bytes, r.slot.data(), r.keep_flag.data(),
                                                r.kept_slots.data(), r.counts.data(), n, stream));
      r.temp.resize(std::max<size_t>(bytes, 1));
      MPM_CUDA_CHECK(cub::DeviceSelect::Flagged(r.temp.data(), bytes, r.slot.data(), r.keep_flag.data(),
                                                r.kept_slots.data(), r.counts.data(), n, stream));
      MPM_CUDA_CHECK(cub::DeviceSelect::Flagged(r.temp.data(), bytes, r.slot.data(), r.leave_flag.data(),
                                                r.leaving_slots.data(), r.counts.data() + 1, n, stream));
      int counts[2] = {0, 0};
      if (n > 0)
        MPM_CUDA_CHECK(cudaMemcpyAsync(counts, r.counts.data(), sizeof(counts), cudaMemcpyDeviceToHost, stream));
      MPM_CUDA_CHECK(cudaStreamSynchronize(stream));
      const int n_kept = counts[0], n_leaving = counts[1];
      r.kept_slots.resize(n_kept);
      r.leaving_slots.resize(n_leaving);

      // The labels, in upload order: those of the points that stay are gathered on the
      // device (original[slot] is a slot's upload-order index), those of the leaving points
      // come down packed in one copy.
      const int *original = impl->order.original_index();
      auto       upload_order_of = [&](const DeviceArray<int> &slots) {
        const int m = static_cast<int>(slots.size());
        r.index.resize(m);
        const int *from = slots.data();
        int       *to   = r.index.data();
        if (m > 0)
          impl->backend.for_each_node(m, [=] MPM_HOST_DEVICE(const int k) { to[k] = original[from[k]]; });
      };
      const int n_labels = static_cast<int>(impl->labels.size());
      upload_order_of(r.leaving_slots);
      r.leaving_labels.resize(static_cast<std::size_t>(n_labels) * n_leaving);
      for (int k = 0; k < n_labels && n_leaving > 0; ++k)
        {
          gather_slots_kernel<double><<<(n_leaving + 255) / 256, 256, 0, stream>>>(
            n_leaving, r.index.data(), impl->labels[k].data(), r.leaving_labels.data() + k * n_leaving);
          MPM_CUDA_CHECK_LAUNCH();
        }
      std::vector<double> packed_labels;
      r.leaving_labels.download(packed_labels); // waits for the gathers
      leaving_labels.resize(n_labels);
      for (int k = 0; k < n_labels; ++k)
        leaving_labels[k].assign(packed_labels.begin() + k * n_leaving, packed_labels.begin() + (k + 1) * n_leaving);
      upload_order_of(r.kept_slots);
      for (DeviceArray<double> &array : impl->labels)
        {
          DeviceArray<double> &gathered = impl->slot_scratch.reals;
          gathered.resize(n_kept);
          if (n_kept > 0)
            {
              gather_slots_kernel<double>
                <<<(n_kept + 255) / 256, 256, 0, stream>>>(n_kept, r.index.data(), array.data(), gathered.data());
              MPM_CUDA_CHECK_LAUNCH();
            }
          array.swap(gathered);
        }
      const int n_dropped = n - n_kept - n_leaving;
      if constexpr (std::is_same<Real, double>::value)
        take_slots<dim>(impl->points, r.leaving_slots, leaving, impl->slot_scratch, stream);
      else
        {
          HostPoints<dim, Real> taken;
          take_slots<dim>(impl->points, r.leaving_slots, taken, impl->slot_scratch, stream);
          convert_points<double>(taken, leaving);
        }
      keep_slots<dim>(impl->points, r.kept_slots, impl->slot_scratch, stream);
      impl->home_cells.resize(0); // append_points sets them
      impl->exchange.first_points = -1;
      return n_dropped;
    }

    template <int dim, typename Real>
    void DeviceEngine<dim, Real>::append_points(const HostPoints<dim, double>          &added_in_double,
                                          const std::vector<std::vector<double>> &added_labels)
    {
      HostPoints<dim, Real>        rounded; // a float engine's copy
      const HostPoints<dim, Real> &added = [&]() -> const HostPoints<dim, Real> & {
        if constexpr (std::is_same<Real, double>::value)
          return added_in_double;
        else
          {
            convert_points<Real>(added_in_double, rounded);
            return rounded;
          }
      }();
      const int          m      = impl->points.size();
      const int          r      = added.size();
      const cudaStream_t stream = impl->backend.get_stream();
      if (added.n_state_variables() != impl->points.n_state_variables())
        throw std::invalid_argument("DeviceEngine::append_points: the added points hold another number of state "
                                    "variables than the device's");
      if (added_labels.size() != impl->labels.size())
        throw std::invalid_argument("DeviceEngine::append_points: not as many label arrays as were uploaded");
      for (std::size_t k = 0; k < added_labels.size(); ++k)
        {
          if (static_cast<int>(added_labels[k].size()) != r)
            throw std::invalid_argument("DeviceEngine::append_points: one label per added point is needed");
          impl->labels[k].resize_preserving(m + r, stream);
          if (r > 0)
            MPM_CUDA_CHECK(cudaMemcpyAsync(impl->labels[k].data() + m, added_labels[k].data(), r * sizeof(double),
                                           cudaMemcpyHostToDevice, stream));
        }
      // In place where the memory held allows (it grows by an eighth when it does not).
      for_each_point_array<dim>(impl->points, added, [&](auto &array, const auto &tail) {
        using T = typename std::decay_t<decltype(array)>::value_type;
        array.resize_preserving(m + r, stream);
        if (r > 0)
          MPM_CUDA_CHECK(
            cudaMemcpyAsync(array.data() + m, tail.data(), r * sizeof(T), cudaMemcpyHostToDevice, stream));
      });
      MPM_CUDA_CHECK(cudaStreamSynchronize(stream)); // before the caller's host arrays go
      // The new upload order, and every point at home in its current cell.
      const int n = m + r;
      impl->order.reset(impl->backend, n);
      impl->steps_since_upload = 0; // sorted by stencil at the next step
      impl->averaging_pending  = false;
      impl->home_cells.resize(n);
      impl->home_by_slot_stale = true;
      const PointsView<dim, Real> p       = impl->points.view();
      const HostLattice<dim>      lattice = impl->host_lattice;
      long                       *home    = impl->home_cells.data();
      impl->backend.for_each_node(n, [=] MPM_HOST_DEVICE(const int i) { home[i] = lattice.cell_of(p.position, i); });
    }

#define MPM_INSTANTIATE(dim, Real) \
  template void DeviceEngine<dim, Real>::set_home_cells(const std::vector<long> &); \
  template double DeviceEngine<dim, Real>::max_distance_outside_home_cells(); \
  template void DeviceEngine<dim, Real>::set_owned_cells(const std::vector<std::uint8_t> &); \
  template int DeviceEngine<dim, Real>::take_leaving_points(HostPoints<dim, double> &, std::vector<std::vector<double>> &); \
  template void DeviceEngine<dim, Real>::append_points(const HostPoints<dim, double> &, const std::vector<std::vector<double>> &);

    MPM_DEVICE_ENGINE_TYPES(MPM_INSTANTIATE)
#undef MPM_INSTANTIATE
  } // namespace cuda
} // namespace mpm
