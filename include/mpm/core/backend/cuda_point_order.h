// Sorting device-resident points by the first lattice node of their scatter stencil.
// Points with the same first node share all their stencil nodes, so after the sort
// neighbouring lanes of a warp hold the same node at every stencil position and the
// CUDA backend's scatter_stencil sums each run of them before one atomic: with 2 points per
// cell and direction, runs of 4 (2D) or 8 (3D) points. Sorting by cell would not do:
// the points of one cell start their GIMP stencils at different nodes.
//
// The sort is a radix sort of the keys (CUB, part of the CUDA toolkit) and a gather of
// every point array through the permutation. The step's results do not depend on the
// order except through the rounding of the nodal sums (which the atomics reorder
// anyway). Each slot remembers the index its point had at the last reset(), so the
// owner can hand the points back in the order it uploaded them.
//
// Include from .cu files only (needs nvcc).
#pragma once

#include <mpm/core/backend/cuda_backend.h>
#include <mpm/core/backend/cuda_storage.h>
#include <mpm/core/views.h>

#include <cub/device/device_radix_sort.cuh>

#include <stdexcept>
#include <type_traits>
#include <vector>

namespace mpm
{
  namespace cuda_detail
  {
    // Up to group_size arrays gathered through one permutation in one launch (the re-sort
    // permutes about 40 point arrays: one launch each cost more than the copies).
    constexpr int group_size = 8;
    template <typename T>
    struct ArrayGroup
    {
      const T *from[group_size];
      T       *to[group_size];
      int      count;
    };
    template <typename T>
    __global__ void gather_group_kernel(const int n, const int *permutation, const ArrayGroup<T> group)
    {
      const int i = static_cast<int>(blockIdx.x * blockDim.x + threadIdx.x);
      if (i >= n)
        return;
      const int source = permutation[i];
      for (int k = 0; k < group_size; ++k)
        if (k < group.count)
          group.to[k][i] = group.from[k][source];
    }

    template <typename T>
    __global__ void scatter_kernel(const int n, const int *destination, const T *in, T *out)
    {
      const int i = static_cast<int>(blockIdx.x * blockDim.x + threadIdx.x);
      if (i < n)
        out[destination[i]] = in[i];
    }
  } // namespace cuda_detail

  template <int dim, typename Real>
  class PointOrder
  {
  public:
    // The points now on the device are the reference order: slot i holds point i.
    void reset(CudaBackend &backend, const int n_points)
    {
      original.resize(n_points);
      int *o = original.data();
      backend.for_each_node(n_points, [=] __device__(const int i) { o[i] = i; });
    }

    // Sorts the points by the first lattice node of their stencil (removed points last),
    // permuting every point array; the point views taken before are invalid afterwards.
    // With first_cells (one flag per lattice cell) and home_cells (each point's lattice cell,
    // in the order of the last reset()), the points whose home cell is flagged come first,
    // each group sorted by stencil: returns how many (exchange_overlap.h), else -1.
    template <typename Shape>
    int sort(CudaBackend &backend, const GridView<dim, Real> &g, DevicePoints<dim, Real> &points,
             const long *home_cells = nullptr, const std::uint8_t *first_cells = nullptr)
    {
      const int n = points.size();
      if (n == 0)
        return first_cells != nullptr ? 0 : -1;
      if (static_cast<int>(original.size()) != n)
        reset(backend, n);
      keys.resize(n);
      sorted_keys.resize(n);
      identity.resize(n);
      permutation.resize(n);

      long n_lattice_nodes = 1;
      for (int d = 0; d < dim; ++d)
        n_lattice_nodes *= g.n_cells[d] + 1;
      // Keys: stencil node, plus the lattice's node count for the second group.
      const bool split = home_cells != nullptr && first_cells != nullptr && 2 * n_lattice_nodes < (1L << 30);
      if (!split)
        first_cells = nullptr;
      const long                  second_group = split ? n_lattice_nodes : 0;
      const long                  n_cells_all  = n_lattice_cells_of(g);
      const int                   removed_key  = static_cast<int>(n_lattice_nodes + second_group);
      const int                  *from_slot    = original.data();
      const PointsView<dim, Real> p            = points.view();
      int *key = keys.data(), *iota = identity.data();
      backend.for_each_node(n, [=] __device__(const int i) {
        iota[i] = i;
        if (p.material[i] < 0)
          {
            key[i] = removed_key;
            return;
          }
        long offset = 0;
        if (first_cells != nullptr)
          {
            const long home = home_cells[from_slot[i]];
            offset          = home >= 0 && home < n_cells_all && first_cells[home] == 0 ? second_group : 0;
          }
        long lattice = 0;
        for (int d = dim - 1; d >= 0; --d)
          {
            // CPDI (not a tensor product): by the point's cell, the linear shape's first node
            using KeyShape    = std::conditional_t<Shape::tensor_product, Shape, LinearShape>;
            constexpr int n_w = KeyShape::n_per_direction;
            int           first;
            Real          w[n_w], dw[n_w];
            KeyShape::weights_1d((p.position[d][i] - g.origin[d]) / g.h, p.domain_half_length[d][i] / g.h, first, w,
                              dw);
            first   = first < 0 ? 0 : (first > g.n_cells[d] ? g.n_cells[d] : first);
            lattice = lattice * (g.n_cells[d] + 1) + first;
          }
        key[i] = static_cast<int>(lattice + offset);
      });

      int end_bit = 1;
      while ((1L << end_bit) <= removed_key)
        ++end_bit;
      size_t temp_bytes = 0;
      MPM_CUDA_CHECK(cub::DeviceRadixSort::SortPairs(nullptr, temp_bytes, keys.data(), sorted_keys.data(),
                                                     identity.data(), permutation.data(), n, 0, end_bit,
                                                     backend.get_stream()));
      if (temp_bytes > temp.size())
        temp.resize(temp_bytes);
      MPM_CUDA_CHECK(cub::DeviceRadixSort::SortPairs(temp.data(), temp_bytes, keys.data(), sorted_keys.data(),
                                                     identity.data(), permutation.data(), n, 0, end_bit,
                                                     backend.get_stream()));

      std::vector<DeviceArray<Real> *> reals;
      std::vector<DeviceArray<int> *>  ints{&original};
      for_each_point_array<dim>(points, points, [&](auto &array, auto &) { collect(array, reals, ints); });
      permute(backend, reals, real_group_scratch);
      permute(backend, ints, int_group_scratch);
      if (!split)
        return -1;
      const int *sorted = sorted_keys.data();
      const int  bound  = static_cast<int>(n_lattice_nodes);
      return backend.reduce_points(
        n, 0, [=] __device__(const int i) { return sorted[i] < bound ? 1 : 0; },
        [] __device__(const int a, const int b) { return a + b; });
    }

    // Every point array copied to the host in the reference order: put back in that order
    // on the device (into the scratch array), then downloaded. Output does this every 0.1 s
    // of P2; on the host the scattered writes of 512,000 points' arrays took longer.
    void download_in_reference_order(CudaBackend &backend, const DevicePoints<dim, Real> &points,
                                     HostPoints<dim, Real> &host)
    {
      const int n = points.size();
      if (static_cast<int>(original.size()) != n)
        throw std::logic_error("PointOrder::download_in_reference_order: the order was not reset for these points");
      host.fields = points.fields;
      if (host.n_state_variables() < points.n_state_variables())
        host.set_n_state_variables(points.n_state_variables());
      for_each_point_array<dim>(points, host, [&](const auto &device, auto &out) {
        auto &scratch = queue_in_reference_order(backend, device, n);
        backend.synchronize();
        scratch.download(out);
      });
    }

    // The same queued on the backend's stream, nothing waited for: each array put back in the
    // reference order into the scratch array, then copied from there to the host, array k
    // of its type (for_each_point_array's order) to to_reals + k n or to_ints + k n. Those
    // must be pinned memory (cudaMallocHost) for the copies to be queued; launches queued
    // later on the stream start after them.
    void queue_download_in_reference_order(CudaBackend &backend, const DevicePoints<dim, Real> &points,
                                           Real *to_reals, int *to_ints)
    {
      const int n = points.size();
      if (static_cast<int>(original.size()) != n)
        throw std::logic_error(
          "PointOrder::queue_download_in_reference_order: the order was not reset for these points");
      if (n == 0)
        return;
      long k_real = 0, k_int = 0;
      for_each_point_array<dim>(points, points, [&](const auto &device, const auto &) {
        auto &scratch = queue_in_reference_order(backend, device, n);
        using T = typename std::decay_t<decltype(device)>::value_type;
        T *to   = nullptr;
        if constexpr (std::is_same<T, int>::value)
          to = to_ints + n * k_int++;
        else
          to = to_reals + n * k_real++;
        MPM_CUDA_CHECK(cudaMemcpyAsync(to, scratch.data(), n * sizeof(T), cudaMemcpyDeviceToHost,
                                       backend.get_stream()));
      });
    }

    // For each slot, the index its point had at the last reset() (the upload order).
    const int *original_index() const { return original.data(); }

  private:
    static long n_lattice_cells_of(const GridView<dim, Real> &g)
    {
      long n = 1;
      for (int d = 0; d < dim; ++d)
        n *= g.n_cells[d];
      return n;
    }

    DeviceArray<int>  keys, sorted_keys, identity, permutation, original, int_scratch;
    DeviceArray<Real> real_scratch;
    DeviceArray<char> temp;
    // One scratch array per slot of a group: each permuted array swaps with its slot's.
    std::vector<DeviceArray<Real>> real_group_scratch = std::vector<DeviceArray<Real>>(cuda_detail::group_size);
    std::vector<DeviceArray<int>>  int_group_scratch  = std::vector<DeviceArray<int>>(cuda_detail::group_size);

    static void collect(DeviceArray<Real> &array, std::vector<DeviceArray<Real> *> &reals,
                        std::vector<DeviceArray<int> *> &)
    {
      reals.push_back(&array);
    }
    static void collect(DeviceArray<int> &array, std::vector<DeviceArray<Real> *> &,
                        std::vector<DeviceArray<int> *> &ints)
    {
      ints.push_back(&array);
    }

    // Every array gathered through the permutation, group_size arrays per launch.
    template <typename T>
    void permute(CudaBackend &backend, const std::vector<DeviceArray<T> *> &arrays,
                 std::vector<DeviceArray<T>> &scratch)
    {
      const int n       = static_cast<int>(permutation.size());
      const int threads = 256;
      for (std::size_t first = 0; first < arrays.size(); first += cuda_detail::group_size)
        {
          cuda_detail::ArrayGroup<T> group{};
          std::vector<int>           slots;
          for (std::size_t a = first; a < arrays.size() && a < first + cuda_detail::group_size; ++a)
            {
              if (arrays[a]->size() == 0)
                continue; // an optional array that these points leave out
              if (static_cast<int>(arrays[a]->size()) != n)
                throw std::logic_error("PointOrder::sort: a point array has another length than the points");
              const int slot = group.count++;
              scratch[slot].resize(n);
              group.from[slot] = arrays[a]->data();
              group.to[slot]   = scratch[slot].data();
              slots.push_back(static_cast<int>(a));
            }
          if (group.count == 0)
            continue;
          cuda_detail::gather_group_kernel<T><<<(n + threads - 1) / threads, threads, 0, backend.get_stream()>>>(
            n, permutation.data(), group);
          MPM_CUDA_CHECK_LAUNCH();
          for (int slot = 0; slot < group.count; ++slot)
            arrays[slots[slot]]->swap(scratch[slot]);
        }
    }

    // One point array put back in the reference order, into the scratch array of its type,
    // queued on the backend's stream. Where the scratch array grows, cudaFree waits for the
    // copies queued before.
    template <typename T>
    DeviceArray<T> &queue_in_reference_order(CudaBackend &backend, const DeviceArray<T> &device, const int n)
    {
      DeviceArray<T> &scratch = scratch_for(device);
      scratch.resize(n);
      if (n > 0)
        {
          const int threads = 256;
          cuda_detail::scatter_kernel<<<(n + threads - 1) / threads, threads, 0, backend.get_stream()>>>(
            n, original.data(), device.data(), scratch.data());
          MPM_CUDA_CHECK_LAUNCH();
        }
      return scratch;
    }

    DeviceArray<Real> &scratch_for(const DeviceArray<Real> &) { return real_scratch; }
    DeviceArray<int>  &scratch_for(const DeviceArray<int> &) { return int_scratch; }
  };
} // namespace mpm
