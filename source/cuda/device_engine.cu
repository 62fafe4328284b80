// nvcc side of mpm::cuda::DeviceEngine (include/mpm/cuda/device_engine.h): the core's
// step.h run by CudaBackend over DevicePoints / DeviceGrid (backend/cuda_storage.h).
// Includes core headers only, never deal.II.
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

namespace mpm
{
  namespace cuda
  {
    int device_count(std::string *why)
    {
      int               n    = 0;
      const cudaError_t code = cudaGetDeviceCount(&n);
      if (code != cudaSuccess)
        {
          if (why)
            *why = std::string(cudaGetErrorName(code)) + ": " + cudaGetErrorString(code);
          (void)cudaGetLastError();
          return 0;
        }
      if (n == 0 && why)
        *why = "the CUDA runtime found no device";
      return n;
    }

    void initialise_device()
    {
      if (cudaFree(nullptr) != cudaSuccess)
        (void)cudaGetLastError(); // reported again, with context, by device_count()
    }

    std::string device_description()
    {
      int device = 0;
      MPM_CUDA_CHECK(cudaGetDevice(&device));
      cudaDeviceProp prop;
      MPM_CUDA_CHECK(cudaGetDeviceProperties(&prop, device));
      char text[256];
      std::snprintf(text, sizeof(text), "%s (sm_%d%d, %d SMs, %.1f GB)", prop.name, prop.major, prop.minor,
                    prop.multiProcessorCount, prop.totalGlobalMem / 1e9);
      return text;
    }

    int use_device_of_local_rank(const int node_local_rank)
    {
      const int n = device_count();
      if (n == 0)
        return 0; // the engine's constructor reports it
      const int device = node_local_rank % n;
      MPM_CUDA_CHECK(cudaSetDevice(device));
      return device;
    }

    bool exchange_overlap_enabled()
    {
      const char *overlap = std::getenv("MPM_CUDA_OVERLAP");
      return overlap == nullptr || overlap[0] != '0';
    }

    namespace
    {
      // Pack and unpack of the exchanged entries, entry by entry (the host's MPI buffers'
      // layout): values[j * count + k] = arrays[k][index[j]].
      // The values travel in the engine's type (float engines exchange half the bytes).
      constexpr int max_exchanged_arrays = 8;
      template <typename Value>
      struct ArrayList
      {
        Value *array[max_exchanged_arrays];
      };
      template <typename Index, typename Value>
      __global__ void pack_kernel(const long n, const int count, const Index *index, const ArrayList<Value> arrays,
                                  Value *values)
      {
        const long j = blockIdx.x * static_cast<long>(blockDim.x) + threadIdx.x;
        if (j >= n * count)
          return;
        values[j] = arrays.array[j % count][index[j / count]];
      }
      template <typename Index, typename Value>
      __global__ void unpack_kernel(const long n, const int count, const Index *index, const Value *values,
                                    const ArrayList<Value> arrays)
      {
        const long j = blockIdx.x * static_cast<long>(blockDim.x) + threadIdx.x;
        if (j >= n * count)
          return;
        arrays.array[j % count][index[j / count]] = values[j];
      }

      // One kind of exchanged entries (nodes or cells): their indices on the device, the
      // packed values on the device and in pinned host memory.
      template <typename Index, typename Value>
      struct Staging
      {
        DeviceArray<Index>  index;
        DeviceArray<Value>  packed;
        Value              *host   = nullptr;
        std::size_t         host_n = 0;

        // The device's time of each exchange, from the end of the work before it to the sums
        // unpacked (host round trip and MPI included): two pairs of events, used in turn, so
        // that the last exchange's pair is read at this one's wait, when it has surely passed.
        cudaEvent_t begin[2] = {}, end[2] = {};
        bool        pending[2] = {false, false};
        int         current    = 0;
        double      seconds    = 0;

        // The overlapped form (begin, end): pack, copies and unpack on a stream of their own
        // (the highest priority, so that its small launches get the first free multiprocessors
        // beside the pass that runs meanwhile); `copied`: the packed values are on the host.
        cudaStream_t side   = nullptr;
        cudaEvent_t  copied = nullptr;

        Staging()                = default;
        Staging(const Staging &) = delete;
        ~Staging()
        {
          if (side != nullptr)
            {
              cudaEventDestroy(copied);
              cudaStreamDestroy(side);
            }
          cudaFreeHost(host);
          for (int k = 0; k < 2; ++k)
            if (begin[k] != nullptr)
              {
                cudaEventDestroy(begin[k]);
                cudaEventDestroy(end[k]);
              }
        }

        // The exchanges' device time so far (waits for the last one).
        double exchange_seconds()
        {
          for (int k = 0; k < 2; ++k)
            if (pending[k])
              {
                MPM_CUDA_CHECK(cudaEventSynchronize(end[k]));
                add(k);
              }
          return seconds;
        }

        void add(const int k)
        {
          float ms = 0;
          MPM_CUDA_CHECK(cudaEventElapsedTime(&ms, begin[k], end[k]));
          seconds += 1e-3 * ms;
          pending[k] = false;
        }

        void set_index(const std::vector<Index> &i) { index.upload(i); }

        // Buffers for count arrays, the events, and the arrays' list.
        ArrayList<Value> prepare(Value *const *arrays, const int count)
        {
          if (count > max_exchanged_arrays)
            throw std::logic_error("DeviceEngine: too many arrays in one exchange");
          const long       total = static_cast<long>(index.size()) * count;
          ArrayList<Value> list{};
          for (int k = 0; k < count; ++k)
            list.array[k] = arrays[k];
          if (packed.size() < static_cast<std::size_t>(total))
            packed.resize(total);
          if (host_n < static_cast<std::size_t>(total))
            {
              cudaFreeHost(host);
              host = nullptr;
              MPM_CUDA_CHECK(cudaMallocHost(&host, total * sizeof(Value)));
              host_n = total;
            }
          if (begin[0] == nullptr)
            for (int k = 0; k < 2; ++k)
              {
                MPM_CUDA_CHECK(cudaEventCreate(&begin[k]));
                MPM_CUDA_CHECK(cudaEventCreate(&end[k]));
              }
          return list;
        }

        // The overlapped exchange, first half: after the work queued so far on the backend's
        // stream, packs the arrays and copies them to the host on the side stream; returns at
        // once. The work queued next on the backend's stream must not touch an exchanged entry.
        void begin_overlapped(CudaBackend &backend, Value *const *arrays, const int count)
        {
          list_in_flight = prepare(arrays, count);
          count_in_flight = count;
          if (side == nullptr)
            {
              int least = 0, greatest = 0;
              MPM_CUDA_CHECK(cudaDeviceGetStreamPriorityRange(&least, &greatest));
              MPM_CUDA_CHECK(cudaStreamCreateWithPriority(&side, cudaStreamNonBlocking, greatest));
              MPM_CUDA_CHECK(cudaEventCreateWithFlags(&copied, cudaEventDisableTiming));
            }
          const long total = static_cast<long>(index.size()) * count;
          MPM_CUDA_CHECK(cudaEventRecord(begin[current], backend.get_stream()));
          MPM_CUDA_CHECK(cudaStreamWaitEvent(side, begin[current], 0));
          if (total > 0)
            {
              pack_kernel<Index, Value><<<(total + 255) / 256, 256, 0, side>>>(static_cast<long>(index.size()), count,
                                                                       index.data(), list_in_flight, packed.data());
              MPM_CUDA_CHECK_LAUNCH();
              MPM_CUDA_CHECK(cudaMemcpyAsync(host, packed.data(), total * sizeof(Value), cudaMemcpyDeviceToHost, side));
            }
          MPM_CUDA_CHECK(cudaEventRecord(copied, side));
        }

        // Second half: waits for the copy, hands it to sum (collective over the ranks), unpacks
        // the sums on the side stream; the backend's stream waits for them before its next work.
        template <typename Sum>
        void end_overlapped(CudaBackend &backend, Sum &&sum)
        {
          const long total = static_cast<long>(index.size()) * count_in_flight;
          MPM_CUDA_CHECK(cudaEventSynchronize(copied));
          if (pending[1 - current])
            add(1 - current);
          sum(host, count_in_flight);
          if (total > 0)
            {
              MPM_CUDA_CHECK(cudaMemcpyAsync(packed.data(), host, total * sizeof(Value), cudaMemcpyHostToDevice, side));
              unpack_kernel<Index, Value><<<(total + 255) / 256, 256, 0, side>>>(static_cast<long>(index.size()),
                                                                         count_in_flight, index.data(), packed.data(),
                                                                         list_in_flight);
              MPM_CUDA_CHECK_LAUNCH();
            }
          MPM_CUDA_CHECK(cudaEventRecord(end[current], side));
          MPM_CUDA_CHECK(cudaStreamWaitEvent(backend.get_stream(), end[current], 0));
          pending[current] = true;
          current          = 1 - current;
        }

        ArrayList<Value> list_in_flight{};
        int       count_in_flight = 0;

        // Packs count arrays, hands the host copy to sum (which replaces it by the sums over
        // the ranks), unpacks; in the stream's order, the host waits for the pack only.
        template <typename Sum>
        void exchange(CudaBackend &backend, Value *const *arrays, const int count, Sum &&sum)
        {
          const ArrayList<Value> list = prepare(arrays, count);
          const long         n       = static_cast<long>(index.size());
          const long         total   = n * count;
          const cudaStream_t stream  = backend.get_stream();
          const int          threads = 256;
          const long         blocks  = (total + threads - 1) / threads;
          MPM_CUDA_CHECK(cudaEventRecord(begin[current], stream));
          if (total > 0)
            {
              pack_kernel<Index, Value><<<blocks, threads, 0, stream>>>(n, count, index.data(), list, packed.data());
              MPM_CUDA_CHECK_LAUNCH();
              MPM_CUDA_CHECK(
                cudaMemcpyAsync(host, packed.data(), total * sizeof(Value), cudaMemcpyDeviceToHost, stream));
            }
          MPM_CUDA_CHECK(cudaStreamSynchronize(stream));
          if (pending[1 - current]) // the last exchange's pair: before this wait in the stream
            add(1 - current);
          sum(host, count); // collective: every rank calls it, with or without entries
          if (total > 0)
            {
              MPM_CUDA_CHECK(
                cudaMemcpyAsync(packed.data(), host, total * sizeof(Value), cudaMemcpyHostToDevice, stream));
              unpack_kernel<Index, Value><<<blocks, threads, 0, stream>>>(n, count, index.data(), packed.data(), list);
              MPM_CUDA_CHECK_LAUNCH();
            }
          MPM_CUDA_CHECK(cudaEventRecord(end[current], stream));
          pending[current] = true;
          current          = 1 - current;
        }
      };

      // The indices i < n with marks[i] != 0, in no fixed order, and their count.
      __global__ void marked_indices_kernel(const long n, const std::uint8_t *marks, int *list, int *count)
      {
        const long i = blockIdx.x * static_cast<long>(blockDim.x) + threadIdx.x;
        if (i < n && marks[i] != 0)
          list[atomicAdd(count, 1)] = static_cast<int>(i);
      }

      // table[at[k]] = k (to_slot) or -1, k < m: a block table's entries set or cleared.
      __global__ void set_table_entries_kernel(const int m, const long *at, int *table, const bool to_slot)
      {
        const int k = static_cast<int>(blockIdx.x * blockDim.x + threadIdx.x);
        if (k < m)
          table[at[k]] = to_slot ? k : -1;
      }

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

      // Whether a material of the table disconnects points (material.h): the averaging
      // finished outside a step then leaves them out, as the step does.
      inline bool disconnects_points(const std::vector<MaterialParameters<double>> &materials)
      {
        for (const MaterialParameters<double> &m : materials)
          if (m.disconnection_volume_ratio > 0)
            return true;
        return false;
      }

      // The step's exchange hook: nothing on one rank, the NodalExchange through the
      // staging buffers otherwise, in the engine's type Real.
      template <typename Real>
      struct ExchangeAdapter
      {
        NodalExchange         *exchange = nullptr;
        CudaBackend           *backend  = nullptr;
        Staging<int, Real>    *nodes    = nullptr;
        Staging<long, Real>   *cells    = nullptr;

        void sum_nodal(Real *const *arrays, const int count) const
        {
          if (exchange != nullptr)
            nodes->exchange(*backend, arrays, count, sum_of(ExchangedEntries::nodes));
        }
        void sum_cells(Real *const *arrays, const int count) const
        {
          if (exchange != nullptr)
            cells->exchange(*backend, arrays, count, sum_of(ExchangedEntries::cells));
        }

        // The overlap (explicit_step's pass_then_sum): the points in the device's order whose
        // home cells reach an exchanged entry come first, first_points of them (-1: not known
        // for the current order and home cells, or overlap off).
        int  first_points = -1;
        int  points_before_overlap() const { return exchange != nullptr ? first_points : -1; }
        void begin_sum(const ExchangedEntries entries, Real *const *arrays, const int count) const
        {
          if (entries == ExchangedEntries::nodes)
            nodes->begin_overlapped(*backend, arrays, count);
          else
            cells->begin_overlapped(*backend, arrays, count);
        }
        void end_sum(const ExchangedEntries entries) const
        {
          if (entries == ExchangedEntries::nodes)
            nodes->end_overlapped(*backend, sum_of(entries));
          else
            cells->end_overlapped(*backend, sum_of(entries));
        }

      private:
        // The host's sum over the ranks of packed values of either kind of entries.
        auto sum_of(const ExchangedEntries entries) const
        {
          return [this, entries](Real *values, const int c) {
            if (entries == ExchangedEntries::nodes)
              exchange->sum_nodal(values, c);
            else
              exchange->sum_cells(values, c);
          };
        }
      };

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
    } // namespace

    // Steps queued behind each other (DeviceEngine::queue_step): each step's time step is
    // computed on the device from the last step's largest speed, and each step's record (its
    // reductions and its time step) is copied into one of two pinned host slots that the
    // host reads when it collects the step, one step behind the device.
    constexpr int queued_record_values = 4; // max speed, power of gravity, max removed speed, dt

    template <typename Real>
    struct QueuedSteps
    {
      DeviceArray<double> records; // two slots of queued_record_values
      DeviceArray<Real>   time_step; // the queued step's dt, in the points' precision
      double             *host = nullptr; // pinned: two slots
      cudaEvent_t         copied[2] = {nullptr, nullptr};
      long                queued = 0, collected = 0;

      void allocate()
      {
        if (host != nullptr)
          return;
        records.resize(2 * queued_record_values);
        time_step.resize(1);
        MPM_CUDA_CHECK(cudaMallocHost(&host, 2 * queued_record_values * sizeof(double)));
        for (cudaEvent_t &e : copied)
          MPM_CUDA_CHECK(cudaEventCreateWithFlags(&e, cudaEventDisableTiming));
      }

      ~QueuedSteps()
      {
        // No throwing from a destructor: errors here are ignored.
        for (cudaEvent_t e : copied)
          if (e != nullptr)
            cudaEventDestroy(e);
        if (host != nullptr)
          cudaFreeHost(host);
      }
    };

    // The queued step's time step, from the last step's record (or the host's speed for the
    // first step queued after one that was not), by the host's rule: the same doubles, the
    // same operations.
    template <typename Real>
    __global__ void queued_time_step_kernel(const TimeStepRule rule, const double time, const double next_output,
                                            const bool speed_from_host, const double host_speed,
                                            const double *last_record, double *record, Real *time_step)
    {
      const double speed = speed_from_host ? host_speed : finite_or_infinite_speed(last_record[0]);
      const double dt    = next_time_step(rule, speed, time, next_output);
      record[3]          = dt;
      *time_step         = static_cast<Real>(dt);
    }

    // The step's reductions (left on the device by the backend) into its record, in double
    // as the host converts them.
    template <typename Real>
    __global__ void queued_step_record_kernel(const StepReduction<Real> *reduction, double *record)
    {
      record[0] = static_cast<double>(reduction->max_speed);
      record[1] = static_cast<double>(reduction->gravity_power);
      record[2] = static_cast<double>(reduction->max_removed_speed);
    }

    // The engine's stream: created (a blocking stream, so that it stays ordered with the
    // legacy stream's copies as before), because a step can be captured into a CUDA graph on
    // a stream of its own only.
    struct OwnStream
    {
      cudaStream_t stream = nullptr;
      OwnStream() { MPM_CUDA_CHECK(cudaStreamCreate(&stream)); }
      ~OwnStream() { cudaStreamDestroy(stream); } // no throwing from a destructor
      OwnStream(const OwnStream &)            = delete;
      OwnStream &operator=(const OwnStream &) = delete;
    };

    // Queued steps whose launches are those of an earlier one (the same settings, arrays and
    // sizes; only the values in device memory differ) replay that step's launches as one CUDA
    // graph: one launch on the host instead of a dozen. A graph per key of the step's launch
    // arguments, the two latest (the re-sort swaps the point arrays between two buffers).
    struct StepGraphs
    {
      struct Entry
      {
        std::vector<unsigned char> key;
        cudaGraphExec_t            exec          = nullptr;
        bool                       pending_after = false; // the host's averaging flag after the step
        long                       last_used     = 0;
      };
      Entry                      entries[2];
      std::vector<unsigned char> last_direct_key; // the last step run without a graph
      long                       captures = 0, replays = 0, uses = 0;
      bool                       enabled  = true; // MPM_CUDA_GRAPHS=0: off

      Entry *find(const std::vector<unsigned char> &key)
      {
        for (Entry &e : entries)
          if (e.exec != nullptr && e.key == key)
            return &e;
        return nullptr;
      }
      Entry &oldest() { return entries[0].last_used <= entries[1].last_used ? entries[0] : entries[1]; }
      void   clear()
      {
        if (entries[0].exec != nullptr || entries[1].exec != nullptr)
          cudaDeviceSynchronize(); // no graph destroyed while it runs (errors ignored: destructor)
        for (Entry &e : entries)
          {
            if (e.exec != nullptr)
              cudaGraphExecDestroy(e.exec);
            e = Entry();
          }
        last_direct_key.clear();
      }
      ~StepGraphs() { clear(); }
    };

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
    StepReduction<double> DeviceEngine<dim, Real>::step(const StepSettings<dim, double> &settings_in_double,
                                                        const double dt_in_double)
    {
      if (impl->queue.queued != impl->queue.collected)
        throw std::logic_error("DeviceEngine::step: a queued step is not collected yet (collect_step)");
      return converted<double>(run_step(converted<Real>(settings_in_double), static_cast<Real>(dt_in_double)));
    }

    template <int dim, typename Real>
    void DeviceEngine<dim, Real>::queue_step(const StepSettings<dim, double> &settings_in_double,
                                             const TimeStepRule &rule, const double time, const double next_output,
                                             const bool speed_from_host, const double host_speed)
    {
      QueuedSteps<Real> &q = impl->queue;
      if (q.queued - q.collected >= 2)
        throw std::logic_error("DeviceEngine::queue_step: two queued steps are not collected yet (collect_step)");
      // The device's speed is the last record's: only that of the one step queued just before.
      if (!speed_from_host && q.queued - q.collected != 1)
        throw std::logic_error("DeviceEngine::queue_step: the speed from the device needs the step before queued "
                               "and not yet collected; otherwise speed_from_host");
      q.allocate();
      const int          slot   = static_cast<int>(q.queued % 2);
      double            *record = q.records.data() + slot * queued_record_values;
      const double      *last   = q.records.data() + (1 - slot) * queued_record_values;
      const cudaStream_t stream = impl->backend.get_stream();
      queued_time_step_kernel<Real><<<1, 1, 0, stream>>>(rule, time, next_output, speed_from_host, host_speed, last,
                                                         record, q.time_step.data());
      MPM_CUDA_CHECK_LAUNCH();
      StepSettings<dim, Real> s = converted<Real>(settings_in_double);
      s.time_step_on_device     = q.time_step.data();
      impl->backend.keep_reductions_on_device = true;
      try
        {
          run_queued_step(s); // the kernels read the device's time step
        }
      catch (...)
        {
          impl->backend.keep_reductions_on_device = false;
          throw;
        }
      impl->backend.keep_reductions_on_device = false;
      queued_step_record_kernel<Real><<<1, 1, 0, stream>>>(
        static_cast<const StepReduction<Real> *>(impl->backend.last_reduction_on_device()), record);
      MPM_CUDA_CHECK_LAUNCH();
      MPM_CUDA_CHECK(cudaMemcpyAsync(q.host + slot * queued_record_values, record,
                                     queued_record_values * sizeof(double), cudaMemcpyDeviceToHost, stream));
      MPM_CUDA_CHECK(cudaEventRecord(q.copied[slot], stream));
      ++q.queued;
    }

    template <int dim, typename Real>
    void DeviceEngine<dim, Real>::run_queued_step(const StepSettings<dim, Real> &s)
    {
      StepGraphs &graphs = impl->graphs;
      const bool  sort_due = sort_interval > 0 && impl->steps_since_upload % sort_interval == 0;
      const bool  timing_due = impl->timed_from >= 0 && impl->n_timed_steps < 5;
      // Several ranks exchange through the host within the step: no graph there.
      if (!graphs.enabled || sort_due || timing_due || impl->exchange.exchange != nullptr)
        {
          run_step(s, Real(0));
          return;
        }
      // What the step's launches depend on besides the values in device memory.
      std::vector<unsigned char> key;
      append_key(key, s);
      append_key(key, impl->view());
      append_key(key, impl->points.view());
      append_key(key, impl->materials.data());
      append_key(key, impl->shape);
      append_key(key, impl->all_laws);
      append_key(key, impl->disconnects);
      append_key(key, impl->averaging_pending);
      append_key(key, impl->backend.block_size);
      const cudaStream_t stream = impl->backend.get_stream();
      ++graphs.uses;
      if (StepGraphs::Entry *e = graphs.find(key))
        {
          MPM_CUDA_CHECK(cudaGraphLaunch(e->exec, stream));
          ++impl->steps_since_upload; // as run_step does
          impl->averaging_pending = e->pending_after;
          e->last_used            = graphs.uses;
          ++graphs.replays;
          return;
        }
      if (key != graphs.last_direct_key)
        {
          // Settings that change every step (a gravity ramp) would capture every step: a
          // graph only for a step whose launches are those of the step before.
          run_step(s, Real(0));
          graphs.last_direct_key = std::move(key);
          return;
        }
      cudaGraph_t graph = nullptr;
      MPM_CUDA_CHECK(cudaStreamBeginCapture(stream, cudaStreamCaptureModeRelaxed));
      try
        {
          run_step(s, Real(0));
        }
      catch (...)
        {
          cudaStreamEndCapture(stream, &graph);
          if (graph != nullptr)
            cudaGraphDestroy(graph);
          throw;
        }
      MPM_CUDA_CHECK(cudaStreamEndCapture(stream, &graph));
      StepGraphs::Entry &e = graphs.oldest();
      if (e.exec != nullptr)
        {
          MPM_CUDA_CHECK(cudaStreamSynchronize(stream)); // the graph may still run a step queued before
          MPM_CUDA_CHECK(cudaGraphExecDestroy(e.exec));
        }
      e.exec = nullptr;
      const cudaError_t instantiated = cudaGraphInstantiate(&e.exec, graph, 0);
      cudaGraphDestroy(graph);
      MPM_CUDA_CHECK(instantiated);
      e.key           = key;
      e.pending_after = impl->averaging_pending;
      e.last_used     = graphs.uses;
      ++graphs.captures;
      MPM_CUDA_CHECK(cudaGraphLaunch(e.exec, stream)); // the captured step runs now
    }

    template <int dim, typename Real>
    long DeviceEngine<dim, Real>::graph_replays() const
    {
      return impl->graphs.replays;
    }

    template <int dim, typename Real>
    long DeviceEngine<dim, Real>::graph_captures() const
    {
      return impl->graphs.captures;
    }

    template <int dim, typename Real>
    QueuedStep DeviceEngine<dim, Real>::collect_step()
    {
      QueuedSteps<Real> &q = impl->queue;
      if (q.collected == q.queued)
        throw std::logic_error("DeviceEngine::collect_step: no step is queued");
      const int slot = static_cast<int>(q.collected % 2);
      MPM_CUDA_CHECK(cudaEventSynchronize(q.copied[slot]));
      const double *record = q.host + slot * queued_record_values;
      ++q.collected;
      return QueuedStep{{record[0], record[1], record[2]}, record[3]};
    }

    template <int dim, typename Real>
    long DeviceEngine<dim, Real>::queued_steps() const
    {
      return impl->queue.queued - impl->queue.collected;
    }

    template <int dim, typename Real>
    StepReduction<Real> DeviceEngine<dim, Real>::run_step(const StepSettings<dim, Real> &s, const Real dt)
    {
      GridView<dim, Real> g = impl->grid.view();
      if (sort_interval > 0 && impl->steps_since_upload % sort_interval == 0)
        {
          // The overlap's split needs every point's home cell.
          const bool split = impl->cells_before_overlap.size() > 0 &&
                             static_cast<int>(impl->home_cells.size()) == impl->points.size();
          const long         *home  = split ? impl->home_cells.data() : nullptr;
          const std::uint8_t *cells = split ? impl->cells_before_overlap.data() : nullptr;
          int                 first = -1;
          with_shape(impl->shape, [&](auto member) { // CPDI: by the point's cell (cuda_point_order.h)
            first = impl->order.template sort<decltype(member)>(impl->backend, g, impl->points, home, cells);
          });
          impl->home_by_slot_stale    = true;
          impl->exchange.first_points = first;
          if (first >= 0 && impl->points.size() > 0)
            {
              impl->first_share_sum += static_cast<double>(first) / impl->points.size();
              ++impl->n_split_sorts;
            }
        }
      ++impl->steps_since_upload;
      if (s.pressure_averaging)
        {
          if (!HasCellArrays<GridView<dim, Real>>::value)
            throw std::runtime_error("pressure averaging is not available in this build of the CUDA engine");
          if (impl->cell_volume.size() == 0)
            {
              impl->cell_volume.resize(impl->n_cell_sums());
              impl->cell_pressure_volume.resize(impl->n_cell_sums());
            }
          g = impl->view();
        }
      const long step_index = impl->steps_since_upload - 1;
      const bool timed      = impl->timed_from >= 0 && step_index >= impl->timed_from && impl->n_timed_steps < 5;
      impl->backend.enable_kernel_timing(timed);
      if (s.affine_state_variable >= 0 && impl->points.n_state_variables() < s.affine_state_variable + dim * dim)
        throw std::invalid_argument("DeviceEngine::step: the affine transfers need the points uploaded with their "
                                    "affine matrices (dim x dim state variables)");
      const bool all_physics =
        impl->all_laws || settings_need_all_physics(s) || shape_needs_all_physics(impl->shape);
      const StepReduction<Real> r =
        all_physics ? explicit_step<dim, DevicePhysics::all>(impl->backend, impl->shape, g, impl->points.view(),
                                                              impl->materials.data(), s, dt, impl->exchange,
                                                              &impl->averaging_pending) :
                      explicit_step<dim>(impl->backend, impl->shape, g, impl->points.view(), impl->materials.data(),
                                         s, dt, impl->exchange, &impl->averaging_pending);
      if (timed)
        {
          const std::vector<float> times = impl->backend.kernel_times_ms();
          impl->launch_ms.resize(std::max(impl->launch_ms.size(), times.size()), 0.0);
          for (size_t k = 0; k < times.size(); ++k)
            impl->launch_ms[k] += times[k];
          if (++impl->n_timed_steps == 5)
            {
              double total = 0;
              for (const double t : impl->launch_ms)
                total += t / 5;
              std::printf("  CUDA per-launch times, steps %ld-%ld, %d points (mean of 5 steps, sum %.3f ms):",
                          impl->timed_from, impl->timed_from + 4, impl->points.size(), total);
              for (size_t k = 0; k < impl->launch_ms.size(); ++k)
                std::printf(" %zu: %.3f", k, impl->launch_ms[k] / 5);
              std::printf("\n");
              std::fflush(stdout);
              impl->backend.enable_kernel_timing(false);
            }
        }
      return r;
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

    template <int dim, typename Real>
    int DeviceEngine<dim, Real>::keep_nodes_near_points(const int block_cells, const FaceConditions<dim> &faces)
    {
      impl->finish_pending_averaging(); // its cell sums live in the arrays replaced below
      // On the device: every point's current cell becomes its home cell (upload order), and
      // the blocks holding a point's cell are marked; only the marks come to the host.
      const int                   n = impl->points.size();
      const PointsView<dim, Real> p = impl->points.view();
      const GridView<dim, Real>   g = impl->grid.view();
      impl->home_cells.resize(n);
      impl->block_marks.resize(n_blocks<dim>(g.n_cells, block_cells));
      impl->block_marks.fill_bytes(0);
      long               *home     = impl->home_cells.data();
      std::uint8_t       *marks    = impl->block_marks.data();
      const int          *original = impl->order.original_index(); // slot -> upload order
      if (n > 0)
        impl->backend.for_each_node(n, [=] MPM_HOST_DEVICE(const int i) {
          Real x[dim];
          for (int d = 0; d < dim; ++d)
            x[d] = p.position[d][i];
          const long cell   = lattice_cell_containing<dim>(g.origin, g.h, g.n_cells, x);
          home[original[i]] = cell;
          if (p.material[i] >= 0)
            marks[block_of_cell<dim>(cell, g.n_cells, block_cells)] = 1; // the same value from every writer
        });
      impl->home_by_slot_stale = true;
      // The marked blocks listed on the device; only the list comes to the host.
      const long n_cell_blocks = n_blocks<dim>(g.n_cells, block_cells);
      impl->holding_list.resize(std::max<long>(std::min<long>(n_cell_blocks, n), 1));
      impl->holding_count.resize(1);
      impl->holding_count.fill_bytes(0);
      const cudaStream_t stream = impl->backend.get_stream();
      if (n > 0)
        {
          marked_indices_kernel<<<static_cast<unsigned int>((n_cell_blocks + 255) / 256), 256, 0, stream>>>(
            n_cell_blocks, marks, impl->holding_list.data(), impl->holding_count.data());
          MPM_CUDA_CHECK_LAUNCH();
        }
      int n_holding = 0;
      MPM_CUDA_CHECK(
        cudaMemcpyAsync(&n_holding, impl->holding_count.data(), sizeof(int), cudaMemcpyDeviceToHost, stream));
      MPM_CUDA_CHECK(cudaStreamSynchronize(stream));
      std::vector<int> holding_ints(n_holding);
      if (n_holding > 0)
        MPM_CUDA_CHECK(cudaMemcpy(holding_ints.data(), impl->holding_list.data(), n_holding * sizeof(int),
                                  cudaMemcpyDeviceToHost));
      if (!impl->chooser)
        impl->chooser = std::make_unique<NodeBlockChooser<dim>>(g.n_cells, block_cells);
      NodeBlockChooser<dim> &chooser = *impl->chooser;
      chooser.choose(std::vector<long>(holding_ints.begin(), holding_ints.end()));
      NodeBox<dim>           box;
      const bool             as_box = box_of_kept_blocks<dim>(g.n_cells, block_cells, chooser.kept_blocks(), box);
      const NodeBlocks<dim> &blocks = chooser.nodes();
      const std::vector<long> box_lattice = as_box ? lattice_of_box_nodes<dim>(g.n_cells, box) : std::vector<long>();
      const std::vector<long> &lattice_of_node = as_box ? box_lattice : blocks.lattice_of_node;
      const long               n_nodes         = static_cast<long>(lattice_of_node.size());
      if (n_nodes > std::numeric_limits<int>::max())
        throw std::length_error("DeviceEngine: more nodes near the points than an int can count");
      std::vector<std::uint8_t> node_fixed, node_friction;
      kept_node_boundary_masks<dim>(faces, g.n_cells, lattice_of_node, node_fixed, node_friction);
      if (as_box)
        impl->grid.set_box(box.lower, box.nodes, node_fixed, node_friction);
      else
        {
          // The device's table: the entries set last cleared, the kept node blocks set to
          // their slots; allocated (every entry -1) at the first use.
          DeviceArray<int> &table = impl->grid.block_slot;
          if (table.size() == 0)
            {
              table.resize(blocks.block_slot.size());
              table.fill_bytes(0xff); // -1
            }
          auto set_entries = [&](const std::vector<long> &at, const bool to_slot) {
            if (at.empty())
              return;
            impl->table_entries.upload(at);
            set_table_entries_kernel<<<static_cast<unsigned int>((at.size() + 255) / 256), 256, 0, stream>>>(
              static_cast<int>(at.size()), impl->table_entries.data(), table.data(), to_slot);
            MPM_CUDA_CHECK_LAUNCH();
            MPM_CUDA_CHECK(cudaStreamSynchronize(stream)); // before the buffer is filled again
          };
          set_entries(impl->table_entries_set, false);
          set_entries(chooser.kept_node_blocks(), true);
          impl->table_entries_set = chooser.kept_node_blocks();
          impl->grid.use_blocks(blocks.block_cells, blocks.node_blocks, node_fixed, node_friction);
        }
      impl->numbered_by_blocks = !as_box;
      impl->cell_sums_at_nodes = true;
      if (impl->cell_volume.size() > 0)
        {
          impl->cell_volume.resize(n_nodes);
          impl->cell_pressure_volume.resize(n_nodes);
        }
      return static_cast<int>(n_nodes);
    }

    template <int dim, typename Real>
    GridView<dim, double> DeviceEngine<dim, Real>::download_kept_nodes(HostGrid<dim, double> &nodes,
                                                                 std::vector<long>     &lattice_of_node) const
    {
      impl->backend.synchronize();
      const DeviceGrid<dim, Real> &dg = impl->grid;
      nodes.h                         = dg.h;
      for (int d = 0; d < dim; ++d)
        {
          nodes.origin[d]  = dg.origin[d];
          nodes.n_cells[d] = dg.n_cells[d];
        }
      std::vector<Real> staging;
      auto              download = [&](const DeviceArray<Real> &from, std::vector<double> &to) {
        from.download(staging);
        to.assign(staging.begin(), staging.end());
      };
      download(dg.mass, nodes.mass);
      for (int d = 0; d < dim; ++d)
        download(dg.velocity[d], nodes.velocity[d]);
      const bool as_box = !impl->numbered_by_blocks;
      lattice_of_node   = as_box ? lattice_of_box_nodes<dim>(dg.n_cells, impl->node_box()) :
                                   impl->chooser->nodes().lattice_of_node;
      GridView<dim, double> view = make_grid_view<dim, double>(nodes);
      view.lattice_to_node       = nullptr;
      if (as_box)
        for (int d = 0; d < dim; ++d)
          {
            view.box_lower[d] = dg.box_lower[d];
            view.box_nodes[d] = dg.box_nodes[d];
          }
      else
        {
          const NodeBlocks<dim> &blocks = impl->chooser->nodes(); // valid until the next choice
          view.set_block_table(blocks.block_slot.data(), blocks.block_cells, blocks.node_blocks);
        }
      return view;
    }

    template <int dim, typename Real>
    bool DeviceEngine<dim, Real>::kept_nodes_are_box() const
    {
      return impl->grid.lattice_order;
    }

    template class DeviceEngine<2, double>;
    template class DeviceEngine<3, double>;
    template class DeviceEngine<2, float>;
    template class DeviceEngine<3, float>;
  } // namespace cuda
} // namespace mpm
