// The device engine's re-sort between ranks (private to source/cuda/device_engine/): the
// scratch its gathers use, the lattice as the host sees it, and the point arrays cut down to,
// or copied out at, given slots.
#pragma once

#include <mpm/core/backend/cuda_backend.h>
#include <mpm/core/backend/cuda_storage.h>
#include <mpm/cuda/device_engine.h>

#include <cstdio>
#include <cstring>
#include <vector>

namespace mpm
{
  namespace cuda
  {
    namespace engine_state
    {
      // to[k] = from[slot[k]], k < m: the points at the given slots, in that order.
      template <typename T>
      __global__ void gather_slots_kernel(const int m, const int *slot, const T *from, T *to)
      {
        const int k = static_cast<int>(blockIdx.x * blockDim.x + threadIdx.x);
        if (k < m)
          to[k] = from[slot[k]];
      }

      // Scratch for the re-sort's gathers, one per element type of the point arrays. Each
      // gathered array swaps with its type's scratch, which then holds the old array's
      // memory for the next one: no allocation and no wait once the sizes have settled.
      struct SlotScratch
      {
        DeviceArray<double> reals;
        DeviceArray<float>  floats;
        DeviceArray<int>    ints;
        DeviceArray<char>   packed; // take_slots: every array's entries, one download
        std::vector<char>   host_packed;

        DeviceArray<double> &of(const DeviceArray<double> &) { return reals; }
        DeviceArray<float>  &of(const DeviceArray<float> &) { return floats; }
        DeviceArray<int>    &of(const DeviceArray<int> &) { return ints; }
      };

      // The re-sort's split of the points (take_leaving_points).
      struct ResortScratch
      {
        DeviceArray<std::uint8_t> keep_flag, leave_flag;
        DeviceArray<int>          slot, kept_slots, leaving_slots, index, counts;
        DeviceArray<double>       leaving_labels; // packed: label array k of leaving point j at k * m + j
        DeviceArray<char>         temp; // CUB's
      };

      // The lattice in double, as the host locates points (BackgroundGrid::lattice_cell_of):
      // the MPI re-sort on the device puts every point in the cell the host will put it in,
      // whatever type the device steps in (a float engine's grid has its origin in float).
      template <int dim>
      struct HostLattice
      {
        double origin[dim];
        double h;
        int    n_cells[dim];

        template <typename Real>
        MPM_HOST_DEVICE long cell_of(const Real *const position[dim], const int i) const
        {
          double x[dim];
          for (int d = 0; d < dim; ++d)
            x[d] = static_cast<double>(position[d][i]);
          return lattice_cell_containing<dim>(origin, h, n_cells, x);
        }
      };

      // Every point array replaced by its entries at the slots, in the slots' order.
      template <int dim, typename Real>
      void keep_slots(DevicePoints<dim, Real> &points, const DeviceArray<int> &slots, SlotScratch &scratch,
                      const cudaStream_t stream)
      {
        const int m = static_cast<int>(slots.size());
        for_each_point_array<dim>(points, points, [&](auto &array, auto &) {
          using T         = typename std::decay_t<decltype(array)>::value_type;
          auto &gathered = scratch.of(array);
          gathered.resize(m);
          if (m > 0)
            {
              gather_slots_kernel<T>
                <<<(m + 255) / 256, 256, 0, stream>>>(m, slots.data(), array.data(), gathered.data());
              MPM_CUDA_CHECK_LAUNCH();
            }
          array.swap(gathered);
        });
      }

      // The entries at the slots copied to the host, in the slots' order: gathered into one
      // packed buffer on the device, one download.
      template <int dim, typename Real>
      void take_slots(const DevicePoints<dim, Real> &points, const DeviceArray<int> &slots,
                      HostPoints<dim, Real> &host, SlotScratch &scratch, const cudaStream_t stream)
      {
        const int m = static_cast<int>(slots.size());
        host.fields = points.fields;
        host.set_n_state_variables(points.n_state_variables()); // the affine transfers' matrices, if any
        host.resize(m);
        size_t bytes = 0;
        for_each_point_array<dim>(points, host, [&](const auto &array, auto &) {
          using T = typename std::decay_t<decltype(array)>::value_type;
          bytes += (m * sizeof(T) + 7) / 8 * 8;
        });
        scratch.packed.resize(bytes);
        size_t at = 0;
        for_each_point_array<dim>(points, host, [&](const auto &array, auto &) {
          using T = typename std::decay_t<decltype(array)>::value_type;
          if (m > 0)
            {
              gather_slots_kernel<T><<<(m + 255) / 256, 256, 0, stream>>>(
                m, slots.data(), array.data(), reinterpret_cast<T *>(scratch.packed.data() + at));
              MPM_CUDA_CHECK_LAUNCH();
            }
          at += (m * sizeof(T) + 7) / 8 * 8;
        });
        scratch.host_packed.resize(bytes);
        if (bytes > 0)
          MPM_CUDA_CHECK(cudaMemcpyAsync(scratch.host_packed.data(), scratch.packed.data(), bytes,
                                         cudaMemcpyDeviceToHost, stream));
        MPM_CUDA_CHECK(cudaStreamSynchronize(stream));
        at = 0;
        for_each_point_array<dim>(points, host, [&](const auto &array, auto &to) {
          using T = typename std::decay_t<decltype(array)>::value_type;
          if (m > 0)
            std::memcpy(to.data(), scratch.host_packed.data() + at, m * sizeof(T));
          at += (m * sizeof(T) + 7) / 8 * 8;
        });
      }
    } // namespace engine_state
  } // namespace cuda
} // namespace mpm
