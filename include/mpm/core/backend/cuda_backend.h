// CUDA backend: how the step's loops run on the device. Same concept as CpuBackend
// (backend/cpu_backend.h): the stages of step.h hand their per-point / per-node
// lambdas (MPM_HOST_DEVICE, compiled by nvcc with --extended-lambda) to
//   for_each_node, gather_points : one thread per item, the item writes only itself;
//   scatter_points                : one thread per point, nodal sums through add(),
//                                   which is atomicAdd on the device (the order of the
//                                   additions, hence the rounding, varies from run to run);
//   reduce_points                 : a two-pass tree reduction on the device; only the
//                                   reduced value (a few bytes) crosses to the host.
// Every launch is checked. Point and node arrays stay on the device
// (backend/cuda_storage.h); this file allocates only the reduction scratch.
//
// Include from .cu files only (needs nvcc).
#pragma once

#if !defined(__CUDACC__)
#  error "mpm/core/backend/cuda_backend.h must be compiled by nvcc (a .cu file)"
#endif

#include <mpm/core/backend/cuda_check.h>
#include <mpm/core/config.h>

#include <cuda_runtime.h>

#include <cstdlib>
#include <cstring>
#include <type_traits>
#include <utility>
#include <vector>

namespace mpm
{
  namespace cuda_detail
  {
    template <typename F>
    __global__ void for_each_kernel(const int n, F f)
    {
      const int i = static_cast<int>(blockIdx.x) * static_cast<int>(blockDim.x) + static_cast<int>(threadIdx.x);
      if (i < n)
        f(i);
    }

    // Block-level tree reduction in shared memory (blockDim.x a power of two).
    template <typename T, typename Combine>
    __device__ T block_reduce(T value, T *shared, Combine &combine)
    {
      const unsigned tid = threadIdx.x;
      shared[tid]        = value;
      __syncthreads();
      for (unsigned s = blockDim.x / 2; s > 0; s >>= 1)
        {
          if (tid < s)
            shared[tid] = combine(shared[tid], shared[tid + s]);
          __syncthreads();
        }
      return shared[0];
    }

    // Pass 1: grid-stride loop, one partial result per block.
    template <typename T, typename F, typename Combine>
    __global__ void reduce_partial_kernel(const int n, const T identity, F f, Combine combine, T *partials)
    {
      extern __shared__ unsigned char shared_bytes[];
      T *shared = reinterpret_cast<T *>(shared_bytes);
      T  acc    = identity;
      for (int i = static_cast<int>(blockIdx.x * blockDim.x + threadIdx.x); i < n;
           i += static_cast<int>(blockDim.x * gridDim.x))
        acc = combine(acc, f(i));
      acc = block_reduce(acc, shared, combine);
      if (threadIdx.x == 0)
        partials[blockIdx.x] = acc;
    }

    // Pass 2: one block combines the partials.
    template <typename T, typename Combine>
    __global__ void reduce_final_kernel(const int n_partials, const T identity, Combine combine, const T *partials,
                                        T *result)
    {
      extern __shared__ unsigned char shared_bytes[];
      T *shared = reinterpret_cast<T *>(shared_bytes);
      T  acc    = identity;
      for (int i = threadIdx.x; i < n_partials; i += blockDim.x)
        acc = combine(acc, partials[i]);
      acc = block_reduce(acc, shared, combine);
      if (threadIdx.x == 0)
        *result = acc;
    }
  } // namespace cuda_detail

  class CudaBackend
  {
  public:
    static constexpr const char *name = "cuda";

    // Threads per block of the item loops (lowered per kernel to what its registers allow);
    // the reduction uses reduce_threads. 128 measured 9% faster than 256 on P1 (H100,
    // 3.2M points, doc/performance.md).
    int block_size = 128;

    explicit CudaBackend(const cudaStream_t stream = nullptr)
      : stream(stream)
    {
      MPM_CUDA_CHECK(cudaMalloc(&scratch, max_reduce_blocks * max_reduction_bytes + max_reduction_bytes));
      MPM_CUDA_CHECK(cudaMallocHost(&host_result, max_reduction_bytes));
      // MPM_CUDA_SYNC=1: synchronise and check after every launch (debugging, sanitizer).
      const char *sync = std::getenv("MPM_CUDA_SYNC");
      sync_every_launch = sync != nullptr && sync[0] == '1';
    }

    CudaBackend(const CudaBackend &)            = delete;
    CudaBackend &operator=(const CudaBackend &) = delete;

    ~CudaBackend()
    {
      // No throwing from a destructor: errors here are ignored.
      for (auto &e : timing_events)
        {
          cudaEventDestroy(e.first);
          cudaEventDestroy(e.second);
        }
      cudaFree(scratch);
      cudaFreeHost(host_result);
    }

    // Scatter-add into a nodal value: an atomic on the device, a plain add on the
    // host (the lambdas are __host__ __device__, so a host instantiation exists).
    template <typename T>
    MPM_HOST_DEVICE static void add(T *target, const T value)
    {
#if defined(__CUDA_ARCH__)
      atomicAdd(target, value);
#else
      *target += value;
#endif
    }

    template <typename F>
    void for_each_node(const int n, F &&f)
    {
      launch(n, std::forward<F>(f));
    }

    template <typename F>
    void gather_points(const int n, F &&f)
    {
      launch(n, std::forward<F>(f));
    }

    template <typename F>
    void scatter_points(const int n, F &&f)
    {
      launch(n, std::forward<F>(f));
    }

    // Reduction on the device; returns the value on the host (synchronises the stream).
    template <typename T, typename F, typename Combine>
    T reduce_points(const int n, const T identity, F &&f, Combine &&combine)
    {
      static_assert(std::is_trivially_copyable<T>::value, "reduce_points needs a trivially copyable type");
      static_assert(sizeof(T) <= max_reduction_bytes, "reduction type too large for the scratch buffer");
      using FT = typename std::decay<F>::type;
      using CT = typename std::decay<Combine>::type;
      T *partials = reinterpret_cast<T *>(scratch);
      T *result   = reinterpret_cast<T *>(static_cast<unsigned char *>(scratch) + max_reduce_blocks * max_reduction_bytes);
      int blocks  = (n + reduce_threads - 1) / reduce_threads;
      if (blocks > max_reduce_blocks)
        blocks = max_reduce_blocks;
      if (blocks < 1)
        blocks = 1;
      begin_timing();
      cuda_detail::reduce_partial_kernel<T, FT, CT>
        <<<blocks, reduce_threads, reduce_threads * sizeof(T), stream>>>(n, identity, f, combine, partials);
      MPM_CUDA_CHECK_LAUNCH();
      cuda_detail::reduce_final_kernel<T, CT>
        <<<1, reduce_threads, reduce_threads * sizeof(T), stream>>>(blocks, identity, combine, partials, result);
      MPM_CUDA_CHECK_LAUNCH();
      end_timing();
      MPM_CUDA_CHECK(cudaMemcpyAsync(host_result, result, sizeof(T), cudaMemcpyDeviceToHost, stream));
      MPM_CUDA_CHECK(cudaStreamSynchronize(stream));
      T value;
      std::memcpy(&value, host_result, sizeof(T));
      return value;
    }

    void synchronize() const { MPM_CUDA_CHECK(cudaStreamSynchronize(stream)); }

    cudaStream_t get_stream() const { return stream; }

    // Optional per-launch timing (benchmarks): while enabled, every launch (a
    // reduction counts as one) records a pair of events; kernel_times_ms() returns
    // the elapsed times in launch order and forgets them.
    void enable_kernel_timing(const bool on) { timing = on; }

    std::vector<float> kernel_times_ms()
    {
      synchronize();
      std::vector<float> times;
      for (size_t i = 0; i < n_timed; ++i)
        {
          float ms = 0;
          MPM_CUDA_CHECK(cudaEventElapsedTime(&ms, timing_events[i].first, timing_events[i].second));
          times.push_back(ms);
        }
      n_timed = 0;
      return times;
    }

  private:
    static constexpr int    reduce_threads      = 256;
    static constexpr int    max_reduce_blocks   = 1024;
    static constexpr size_t max_reduction_bytes = 128; // PointTotals<3, double> is 96

    cudaStream_t stream;
    void        *scratch     = nullptr;
    void        *host_result = nullptr;
    bool         sync_every_launch = false;

    bool                                       timing  = false;
    size_t                                     n_timed = 0;
    std::vector<std::pair<cudaEvent_t, cudaEvent_t>> timing_events;

    template <typename F>
    void launch(const int n, F &&f)
    {
      if (n <= 0)
        return;
      using FT = typename std::decay<F>::type;
      // The largest block this kernel can be launched with (registers per thread).
      static const int max_threads = [] {
        cudaFuncAttributes attributes;
        MPM_CUDA_CHECK(cudaFuncGetAttributes(&attributes, cuda_detail::for_each_kernel<FT>));
        return attributes.maxThreadsPerBlock;
      }();
      const int threads = block_size < max_threads ? block_size : max_threads;
      const int blocks  = (n + threads - 1) / threads;
      begin_timing();
      cuda_detail::for_each_kernel<FT><<<blocks, threads, 0, stream>>>(n, f);
      MPM_CUDA_CHECK_LAUNCH();
      end_timing();
    }

    void begin_timing()
    {
      if (!timing)
        return;
      if (n_timed == timing_events.size())
        {
          std::pair<cudaEvent_t, cudaEvent_t> e;
          MPM_CUDA_CHECK(cudaEventCreate(&e.first));
          MPM_CUDA_CHECK(cudaEventCreate(&e.second));
          timing_events.push_back(e);
        }
      MPM_CUDA_CHECK(cudaEventRecord(timing_events[n_timed].first, stream));
    }

    void end_timing()
    {
      if (sync_every_launch)
        MPM_CUDA_CHECK(cudaStreamSynchronize(stream));
      if (!timing)
        return;
      MPM_CUDA_CHECK(cudaEventRecord(timing_events[n_timed].second, stream));
      ++n_timed;
    }
  };
} // namespace mpm
