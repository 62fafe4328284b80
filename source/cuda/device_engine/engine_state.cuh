// The device engine's state, shared by its source files (one per job): the Impl of
// mpm::cuda::DeviceEngine (include/mpm/cuda/device_engine.h) and the pieces it holds (the
// exchange's staging, the re-sort's scratch, the queued steps and their CUDA graphs, the
// output's pinned buffers). Private to source/cuda/device_engine/; includes core headers only.
#pragma once

#include "exchange_staging.cuh"
#include "queued_steps.cuh"
#include "resort_scratch.cuh"

#include <mpm/core/backend/cuda_backend.h>
#include <mpm/core/backend/cuda_point_order.h>
#include <mpm/core/backend/cuda_storage.h>
#include <mpm/core/active_nodes.h>
#include <mpm/core/exchange_overlap.h>
#include <mpm/core/migration.h>
#include <mpm/core/precision.h>
#include <mpm/core/time_step_rule.h>
#include <mpm/cuda/device_engine.h>

#include <cub/device/device_select.cuh>

#include <algorithm>
#include <atomic>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <stdexcept>
#include <type_traits>
#include <utility>

#define MPM_DEVICE_ENGINE_TYPES(X) \
  X(2, double)                     \
  X(3, double)                     \
  X(2, float)                      \
  X(3, float)

namespace mpm
{
  namespace cuda
  {
    namespace engine_state
    {
      // Whether a material of the table disconnects points (material.h): the averaging
      // finished outside a step then leaves them out, as the step does.
      inline bool disconnects_points(const std::vector<MaterialParameters<double>> &materials)
      {
        for (const MaterialParameters<double> &m : materials)
          if (m.disconnection_volume_ratio > 0)
            return true;
        return false;
      }

      // Cell arrays of the pressure averaging, where this version of GridView has them.
      template <typename G, typename = void>
      struct HasCellArrays : std::false_type
      {};
      template <typename G>
      struct HasCellArrays<G, decltype((void)std::declval<G &>().cell_volume, void())> : std::true_type
      {};

      template <typename G, typename Real>
      void set_cell_arrays(G &g, Real *volume, Real *pressure_volume, std::true_type)
      {
        g.cell_volume          = volume;
        g.cell_pressure_volume = pressure_volume;
      }
      template <typename G, typename Real>
      void set_cell_arrays(G &, Real *, Real *, std::false_type)
      {}
    } // namespace engine_state
    using namespace engine_state;

    // Pinned host memory that output downloads (begin_download_points) come down into while
    // the steps go on, and the event that marks their copies done. Shared with the function
    // that finishes a download, so that it stays valid if the engine is gone first.
    template <typename Real>
    struct OutputDownload
    {
      Real             *reals = nullptr;
      int              *ints  = nullptr;
      std::size_t       n_reals = 0, n_ints = 0; // capacities
      cudaEvent_t       copied  = nullptr;
      std::atomic<bool> unfinished{false}; // begun, its function not run yet

      OutputDownload() { MPM_CUDA_CHECK(cudaEventCreateWithFlags(&copied, cudaEventDisableTiming)); }
      OutputDownload(const OutputDownload &) = delete;
      ~OutputDownload()
      {
        cudaEventSynchronize(copied); // no pinned memory freed under a copy (errors ignored: destructor)
        cudaEventDestroy(copied);
        cudaFreeHost(reals);
        cudaFreeHost(ints);
      }

      // Room for at least the given numbers of values; the last copies are done.
      void reserve(const std::size_t reals_needed, const std::size_t ints_needed)
      {
        grow(reals, n_reals, reals_needed);
        grow(ints, n_ints, ints_needed);
      }

    private:
      template <typename T>
      void grow(T *&buffer, std::size_t &capacity, const std::size_t needed)
      {
        if (needed <= capacity)
          return;
        MPM_CUDA_CHECK(cudaEventSynchronize(copied));
        MPM_CUDA_CHECK(cudaFreeHost(buffer));
        buffer   = nullptr;
        capacity = 0;
        MPM_CUDA_CHECK(cudaMallocHost(&buffer, needed * sizeof(T)));
        capacity = needed;
      }
    };

    // Appends the bytes of a value to a key.
    template <typename T>
    void append_key(std::vector<unsigned char> &key, const T &value)
    {
      static_assert(std::is_trivially_copyable<T>::value, "a key's part is copied byte by byte");
      const auto *bytes = reinterpret_cast<const unsigned char *>(&value);
      key.insert(key.end(), bytes, bytes + sizeof(T));
    }

    template <int dim, typename Real>
    struct DeviceEngine<dim, Real>::Impl
    {
      OwnStream                    own_stream;
      CudaBackend                  backend{own_stream.stream};
      DeviceGrid<dim, Real>        grid;
      DevicePoints<dim, Real>      points;
      PointOrder<dim, Real>        order; // points sorted by stencil every sort_interval steps
      long                         steps_since_upload = 0;
      // MPM_CUDA_KERNEL_TIMES=N: per-launch times of steps N..N+4 after an upload, printed
      // once (what the profiler would say, without one; doc/performance.md).
      long                         timed_from = -1, n_timed_steps = 0;
      std::vector<double>          launch_ms;
      DeviceMaterials<Real>        materials;
      DeviceArray<Real>            cell_volume, cell_pressure_volume;
      long                         n_lattice_cells = 1;
      HostLattice<dim>             host_lattice;
      ShapeFunction                shape;
      // A material asks for Hencky's law or Mohr-Coulomb: the step runs the kernels that hold
      // them (step.h's DevicePhysics).
      bool                         all_laws = false;
      // A material disconnects points (disconnects_points).
      bool                         disconnects = false;
      Staging<int, Real>           exchanged_nodes;
      Staging<long, Real>          exchanged_cells;
      ExchangeAdapter<Real>        exchange;
      DeviceArray<long>            home_cells; // several ranks: in upload order
      // The same in the device's current point order (the per-step distance check reads them
      // coalesced); gathered again after each change of order.
      DeviceArray<long>            home_by_slot;
      bool                         home_by_slot_stale = true;
      std::vector<DeviceArray<double>> labels; // several ranks: ids, initial positions; in upload order
      DeviceArray<std::uint8_t>    owned_cells; // several ranks: 1 for each lattice cell this rank owns
      // Several ranks: 1 for each lattice cell whose points can add into an exchanged entry
      // (exchange_overlap.h); those points come first in each sort, and the passes before an
      // exchange overlap it (explicit_step). Empty where the exchange is not overlapped
      // (MPM_CUDA_OVERLAP=0). The share of points that came first, summed over the sorts.
      DeviceArray<std::uint8_t>    cells_before_overlap;
      double                       first_share_sum = 0;
      long                         n_split_sorts   = 0;
      // The re-sort's (take_leaving_points) flags, slot lists and gathers' scratch: kept
      // between re-sorts.
      ResortScratch                resort;
      SlotScratch                  slot_scratch;
      // The device index of each host node (-1: not in the lattice).
      std::vector<int>             slab_of_host;
      // The last step's pressure averaging is left to the next step's P2G (explicit_step);
      // download_points finishes it first.
      bool                         averaging_pending = false;
      // Nodes near the points (keep_nodes_near_points): chosen on the host (the chooser
      // holds the block table and the lattice index of each node), numbered as a box of the
      // lattice (grid.box_lower, box_nodes) or through the block table, whose device copy
      // has the entries table_entries_set; the cell sums at the nodes.
      std::unique_ptr<NodeBlockChooser<dim>> chooser;
      bool                         numbered_by_blocks = false;
      std::vector<long>            table_entries_set;
      DeviceArray<long>            table_entries; // upload buffer
      DeviceArray<int>             holding_list, holding_count;
      bool                         cell_sums_at_nodes = false;
      DeviceArray<std::uint8_t>    block_marks; // blocks holding a point's cell (keep_nodes_near_points)
      QueuedSteps<Real>            queue; // steps queued behind each other (queue_step)
      StepGraphs                   graphs; // queued steps replayed as CUDA graphs
      std::shared_ptr<OutputDownload<Real>> output_download; // begin_download_points, from the first

      // The device grid's view, with the averaging's cell arrays where they exist.
      GridView<dim, Real> view()
      {
        GridView<dim, Real> g = grid.view();
        if (cell_volume.size() > 0)
          set_cell_arrays(g, cell_volume.data(), cell_pressure_volume.data(), HasCellArrays<GridView<dim, Real>>());
        g.cell_sums_at_nodes = cell_sums_at_nodes;
        return g;
      }

      // Entries of the pressure averaging's cell sums: one per lattice cell, or per node.
      long n_cell_sums() const { return cell_sums_at_nodes ? grid.n_nodes() : n_lattice_cells; }

      // The box the device's nodes are, where they have no lookup.
      NodeBox<dim> node_box() const
      {
        NodeBox<dim> box;
        for (int d = 0; d < dim; ++d)
          {
            box.lower[d] = grid.box_lower[d];
            box.nodes[d] = grid.box_nodes[d];
          }
        return box;
      }

      // Lattice index of device node b.
      long lattice_of_device_node(const long b) const
      {
        return numbered_by_blocks ? chooser->nodes().lattice_of_node[b] : node_box().lattice_of(b, grid.n_cells);
      }

      // Applies the last step's averaging if the next step's P2G was to do it.
      void finish_pending_averaging()
      {
        if (averaging_pending)
          {
            stages::finish_pressure_averaging(backend, view(), points.view(), disconnects ? materials.data() : nullptr);
            averaging_pending = false;
          }
      }
    };
  } // namespace cuda
} // namespace mpm
