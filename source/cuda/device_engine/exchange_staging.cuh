// The device engine's side of the exchange between ranks (private to source/cuda/device_engine/):
// the exchanged entries packed on the device into pinned host buffers and back, and the step's
// exchange hook over them.
#pragma once

#include <mpm/core/backend/cuda_backend.h>
#include <mpm/core/backend/cuda_storage.h>
#include <mpm/cuda/device_engine.h>

#include <cstdio>
#include <cstring>
#include <vector>
#include <atomic>
#include <chrono>

namespace mpm
{
  namespace cuda
  {
    namespace engine_state
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
    } // namespace engine_state
  } // namespace cuda
} // namespace mpm
