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
#include <mpm/core/interpolation.h>
#include <mpm/core/stencil_contribution.h>

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

    // The gather loops (G2P kinematics with the constitutive update: 146 registers
    // unbounded, 18% occupancy on P1) with a register cap from a minimum number of
    // resident blocks of gather_block_size threads; 0: no cap. 5 blocks (102 registers,
    // some spilling) took P1's kinematics from 6.27 to 4.80 ms per step at 12.8M points,
    // 4 blocks to 5.23 ms (H100, doc/performance.md).
#if !defined(MPM_GATHER_MIN_BLOCKS)
#  define MPM_GATHER_MIN_BLOCKS 5
#endif
#if MPM_GATHER_MIN_BLOCKS > 0
    constexpr int gather_block_size = 128;
    template <typename F>
    __global__ void __launch_bounds__(gather_block_size, MPM_GATHER_MIN_BLOCKS) gather_kernel_bounded(const int n, F f)
    {
      const int i = static_cast<int>(blockIdx.x) * static_cast<int>(blockDim.x) + static_cast<int>(threadIdx.x);
      if (i < n)
        f(i);
    }
#endif

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
    // Shared memory where the lanes of a warp stage the values they add into one node
    // (CudaBackend::add_to_node): 8 warps x 32 lanes x 64 bytes, 16 KB per block of a
    // kernel that scatters.
    constexpr int    max_staging_threads       = 256;
    constexpr size_t max_staged_bytes_per_lane = 64;
    __device__ inline unsigned char *staging_area()
    {
      __shared__ alignas(16) unsigned char bytes[max_staging_threads * max_staged_bytes_per_lane];
      return bytes;
    }

    // Shared memory where the lanes of a block stage their stencil records for
    // CudaBackend::scatter_stencil: up to max_record_values per lane (3D GIMP P2G: 35),
    // max_stencil_threads lanes. One array per kernel, whichever scatters it instantiates.
    constexpr int max_stencil_threads = 128;
    constexpr int max_record_values   = 35;
    template <typename Real>
    __device__ inline Real *stencil_records()
    {
      __shared__ Real records[max_stencil_threads * max_record_values];
      return records;
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

    // Scatter adds (step.h): targets[k][entry] += values[k] for k < K, called by every
    // point for each node (or cell) it adds into. On the device, lanes of a warp that
    // add into the same entry in a run of neighbouring lanes sum their values first: the
    // run stages its K values per lane in shared memory, then lane j of the run sums value
    // j (j + length, ... for runs shorter than K) over the run's lanes and issues the one
    // atomicAdd. Points sorted by stencil (backend/cuda_point_order.h) come in runs of 4
    // (2D) or 8 (3D), so the L2 sees that many times fewer atomics, for a few shared-memory
    // accesses per value. An unsorted warp is still right, only less reduced. A warp that
    // is not fully converged (a removed point, the last partial warp, a node outside the
    // lattice), or a block larger than the staging area, adds lane by lane. On the host
    // (the lambdas are __host__ __device__, so a host instantiation exists) a plain +=.
    template <int K, typename T>
    MPM_HOST_DEVICE static void add_to_node(T *const *targets, const int entry, const T *values)
    {
#if defined(__CUDA_ARCH__)
      using cuda_detail::max_staged_bytes_per_lane;
      using cuda_detail::max_staging_threads;
      static_assert(K * sizeof(T) <= max_staged_bytes_per_lane, "too many values per node for the staging area");
      constexpr unsigned all = 0xffffffffu;
      const int          lane = static_cast<int>(threadIdx.x) & 31;
      bool               runs = __activemask() == all && blockDim.x <= max_staging_threads;
      unsigned           heads = 0;
      if (runs)
        {
          const int previous = __shfl_up_sync(all, entry, 1);
          heads              = __ballot_sync(all, lane == 0 || previous != entry);
          runs               = heads != all; // all heads: no run longer than one lane
        }
      if (!runs)
        {
          for (int k = 0; k < K; ++k)
            atomicAdd(&targets[k][entry], values[k]);
          return;
        }
      const int      first  = 31 - __clz(static_cast<int>(heads & (all >> (31 - lane))));
      const unsigned later  = lane == 31 ? 0u : heads & (all << (lane + 1));
      const int      last   = later != 0u ? __ffs(static_cast<int>(later)) - 2 : 31;
      const int      length = last - first + 1;
      T *staged = reinterpret_cast<T *>(cuda_detail::staging_area()) + (threadIdx.x >> 5) * 32 * K;
      for (int k = 0; k < K; ++k)
        staged[lane * K + k] = values[k];
      __syncwarp();
      for (int k = lane - first; k < K; k += length)
        {
          T sum = staged[first * K + k];
          for (int l = first + 1; l <= last; ++l)
            sum += staged[l * K + k];
          atomicAdd(&targets[k][entry], sum);
        }
      __syncwarp(); // the staging area is reused by the next call
#else
      for (int k = 0; k < K; ++k)
        targets[k][entry] += values[k];
#endif
    }

    // A point's contribution into each node of its stencil (stencil_contribution.h),
    // called by every thread of a scatter_points loop for its point. On the device the
    // lanes of a warp whose stencils start at the same node (a run: points sorted by
    // stencil, backend/cuda_point_order.h, come in runs of 4 in 2D and 8 in 3D) share the
    // work by nodes instead of by points: each lane stages its 1D weights and
    // coefficients in shared memory, then lane j of a run of length R sums stencil nodes
    // j, j + R, ... over the run's points and issues one atomicAdd per value and node.
    // A point then costs about one node's worth of weight products per node, with no
    // per-node reduction, and the L2 sees one atomic per run, node and value. N and grad N
    // come from stencil_weight_at and the values from StencilContribution::values: the
    // same arithmetic as the CPU. Points whose stencil is not wholly inside the lattice
    // are runs of one. A warp that is not fully converged (a removed point, the last
    // partial warp) or a block larger than the staging area adds point by point.
    template <int dim, typename Shape, int K, int Kg, typename Real>
    MPM_HOST_DEVICE static void scatter_stencil(const GridView<dim, Real> &g, const Real x[dim], const Real lp[dim],
                                                Real *const *targets, const StencilContribution<dim, K, Kg, Real> &c)
    {
#if defined(__CUDA_ARCH__)
      constexpr int      n         = Shape::n_per_direction;
      constexpr int      n_stencil = dim == 2 ? n * n : n * n * n;
      constexpr int      n_w       = dim * n;                  // 1D weights, then derivatives if Kg > 0
      constexpr int      at_c_N    = (Kg > 0 ? 2 : 1) * n_w;   // then c_N[K], then c_grad[Kg][dim]
      constexpr int      at_c_grad = at_c_N + K;
      constexpr int      stride    = (at_c_grad + Kg * dim) | 1;
      constexpr unsigned all       = 0xffffffffu;
      // Odd: the 16 lanes of a half-warp's 8-byte accesses fall in different banks.
      static_assert(stride % 2 == 1 && stride <= cuda_detail::max_record_values, "record too long");
      if (__activemask() != all || blockDim.x > cuda_detail::max_stencil_threads)
        {
          for_each_stencil_node<dim, Shape>(g, x, lp, [&](const int node, const Real N, const Real *grad) {
            Real values[K];
            c.values(N, grad, values);
            for (int v = 0; v < K; ++v)
              atomicAdd(&targets[v][node], values[v]);
          });
          return;
        }
      const int  lane  = static_cast<int>(threadIdx.x) & 31;
      const Real inv_h = Real(1) / g.h;
      int        first[dim];
      Real       w[dim][n], dw[dim][n];
      for (int d = 0; d < dim; ++d)
        Shape::weights_1d((x[d] - g.origin[d]) * inv_h, lp[d] * inv_h, first[d], w[d], dw[d]);
      long       lattice_stride[dim], base;
      const bool inside = stencil_base<dim, n>(g, first, lattice_stride, base);

      // Runs of neighbouring lanes with the same first stencil node.
      const long     key   = inside ? base : -1 - lane;
      const long     prev  = __shfl_up_sync(all, key, 1);
      const unsigned heads = __ballot_sync(all, lane == 0 || prev != key);
      const int      head  = 31 - __clz(static_cast<int>(heads & (all >> (31 - lane))));
      const unsigned later = lane == 31 ? 0u : heads & (all << (lane + 1));
      const int      last  = later != 0u ? __ffs(static_cast<int>(later)) - 2 : 31;
      const int      length = last - head + 1;

      Real *records = cuda_detail::stencil_records<Real>() + (threadIdx.x & ~31u) * stride;
      Real *mine    = records + lane * stride;
      for (int d = 0; d < dim; ++d)
        for (int j = 0; j < n; ++j)
          {
            mine[d * n + j] = w[d][j];
            if (Kg > 0)
              mine[n_w + d * n + j] = dw[d][j];
          }
      for (int k = 0; k < K; ++k)
        mine[at_c_N + k] = c.c_N[k];
      for (int k = 0; k < Kg; ++k)
        for (int e = 0; e < dim; ++e)
          mine[at_c_grad + k * dim + e] = c.c_grad[k][e];
      __syncwarp();

      for (int s = lane - head; s < n_stencil; s += length)
        {
          const int k[3] = {s % n, (s / n) % n, s / (n * n)};
          Real      sum[K];
          for (int v = 0; v < K; ++v)
            sum[v] = Real(0);
          for (int l = head; l <= last; ++l)
            {
              const Real *record = records + l * stride;
              Real        wk[dim], dwk[dim], grad[dim];
              for (int d = 0; d < dim; ++d)
                {
                  wk[d]  = record[d * n + k[d]];
                  dwk[d] = Kg > 0 ? record[n_w + d * n + k[d]] : Real(0);
                }
              const Real N = stencil_weight_at<dim>(wk, dwk, inv_h, grad);
              StencilContribution<dim, K, Kg, Real> point;
              for (int v = 0; v < K; ++v)
                point.c_N[v] = record[at_c_N + v];
              for (int v = 0; v < Kg; ++v)
                for (int e = 0; e < dim; ++e)
                  point.c_grad[v][e] = record[at_c_grad + v * dim + e];
              Real values[K];
              point.values(N, grad, values);
              for (int v = 0; v < K; ++v)
                sum[v] += values[v];
            }
          int node;
          if (inside)
            {
              long offset = 0;
              for (int d = 0; d < dim; ++d)
                offset += k[d] * lattice_stride[d];
              node = g.lattice_to_node[base + offset];
            }
          else
            {
              int idx[dim];
              for (int d = 0; d < dim; ++d)
                idx[d] = first[d] + k[d];
              node = g.node(idx);
            }
          if (node >= 0) // else absent, or outside the lattice where the weight is zero
            for (int v = 0; v < K; ++v)
              atomicAdd(&targets[v][node], sum[v]);
        }
      __syncwarp(); // the records are reused by the next call
#else
      add_contribution<CudaBackend>([&](auto &&visit) { for_each_stencil_node<dim, Shape>(g, x, lp, visit); }, targets,
                                    c);
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
#if MPM_GATHER_MIN_BLOCKS > 0
      if (n <= 0)
        return;
      using FT = typename std::decay<F>::type;
      constexpr int threads = cuda_detail::gather_block_size;
      begin_timing();
      cuda_detail::gather_kernel_bounded<FT><<<(n + threads - 1) / threads, threads, 0, stream>>>(n, f);
      MPM_CUDA_CHECK_LAUNCH();
      end_timing();
#else
      launch(n, std::forward<F>(f));
#endif
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
      // Whole warps: add_to_node's lane arithmetic assumes lane = threadIdx.x % 32.
      const int threads = ((block_size < max_threads ? block_size : max_threads) / 32) * 32;
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
