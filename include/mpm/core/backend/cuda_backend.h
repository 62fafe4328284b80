// CUDA backend: how the step's loops run on the device. Same concept as CpuBackend
// (backend/cpu_backend.h): the stages of step.h hand their per-point / per-node
// lambdas (MPM_HOST_DEVICE, compiled by nvcc with --extended-lambda) to
//   for_each_node, gather_points : one thread per item, the item writes only itself;
//   scatter_points                : one thread per point; a point's stencil sums through
//                                   scatter_stencil, a cell's through add_to_node, both
//                                   ending in atomicAdd on the device (the order of the
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

    // The gather loops (G2P kinematics with the constitutive update) with a register cap
    // from a minimum number of resident blocks of gather_block_size threads, per precision;
    // MPM_GATHER_MIN_BLOCKS sets both (0: no cap). FP64 4 blocks (128 registers): the
    // standard kernels' kinematics spills nothing since Mohr-Coulomb and U's domains left
    // them, and P1's took 3.25 ms per step at 12.8M points against 3.67 ms with 5 blocks;
    // FP32 5 blocks (96 registers, no spills): 1.80 ms against 1.90 ms with 4 (H100,
    // 2026-12-05, doc/performance.md).
#if defined(MPM_GATHER_MIN_BLOCKS)
#  define MPM_GATHER_MIN_BLOCKS_FP64 MPM_GATHER_MIN_BLOCKS
#  define MPM_GATHER_MIN_BLOCKS_FP32 MPM_GATHER_MIN_BLOCKS
#else
#  define MPM_GATHER_MIN_BLOCKS_FP64 4
#  define MPM_GATHER_MIN_BLOCKS_FP32 5
#endif
#if MPM_GATHER_MIN_BLOCKS_FP64 > 0
    constexpr int gather_block_size = 128;
    // Real: the precision of the points the loop reads (void: FP64's cap).
    template <typename Real>
    constexpr int gather_min_blocks()
    {
      return std::is_same_v<Real, float> ? MPM_GATHER_MIN_BLOCKS_FP32 : MPM_GATHER_MIN_BLOCKS_FP64;
    }
    template <int min_blocks, typename F>
    __global__ void __launch_bounds__(gather_block_size, min_blocks) gather_kernel_bounded(const int n, F f)
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
    // CudaBackend::scatter_stencil: capacity values per lane (max_record_values, 3D GIMP
    // P2G: 34, unless the kernel's only scatter asks for its own record's length),
    // max_stencil_threads lanes, 16-byte aligned for paired loads; and per warp a table of
    // its runs (head lane, length, first stencil node). One array per capacity that a
    // kernel instantiates: the scatters of one kernel (P2G's three forms) share the largest.
    constexpr int max_stencil_threads = 128;
    constexpr int max_record_values   = 34;
    constexpr int run_entry_ints      = 5; // head, length, first[3]
    template <typename Real, int capacity = max_record_values>
    __device__ inline Real *stencil_records()
    {
      __shared__ alignas(16) Real records[max_stencil_threads * capacity];
      return records;
    }
    __device__ inline int *stencil_runs()
    {
      __shared__ int runs[max_stencil_threads * run_entry_ints];
      return runs;
    }
    // Two values in one 8- or 16-byte shared-memory load.
    template <typename Real>
    struct Pair;
    template <>
    struct Pair<double>
    {
      using type = double2;
    };
    template <>
    struct Pair<float>
    {
      using type = float2;
    };
  } // namespace cuda_detail

  class CudaBackend
  {
  public:
    static constexpr const char *name = "cuda";
    // add_to_node is atomic: any per-point loop may scatter into cells (step.h).
    static constexpr bool atomic_scatter = true;

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
    // point for the entry it adds into (the pressure averaging's cell sums; a point's
    // stencil goes through scatter_stencil below). On the device, lanes of a warp that
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
    // lanes of a warp share the work by (run, node) instead of by point. A run is a
    // stretch of neighbouring lanes whose stencils start at the same node (points sorted
    // by stencil, backend/cuda_point_order.h, come in runs of 4 in 2D and 8 in 3D): its
    // points add into the same nodes. Each lane stages its 1D weights and coefficients in
    // shared memory; then the warp's tasks (every run x every stencil node) are dealt
    // round robin to the 32 lanes, and a task sums its node's values over the run's points
    // and issues one atomicAdd per value. So a point costs one node's weight products per
    // node, there is no per-node reduction, the L2 sees one atomic per run, node and
    // value, and runs cut by warp boundaries or of uneven length keep the lanes evenly
    // busy. 3D GIMP (27 nodes) goes through the runs in order instead, lane s holding
    // node s, and passes the sums of the layers that the next run along x shares down x
    // (half the atomics; see the branch below). Sums that are exactly zero are not added.
    // N and grad N come from stencil_weight_at and the values from
    // StencilContribution::values: the same arithmetic as the CPU. Points whose stencil
    // is not wholly inside the lattice are runs of one. A warp that is not fully
    // converged (a removed point, the last partial warp) or a block larger than the
    // staging area adds point by point.
    // CPDI (not a tensor product: corner by corner, cpdi.h) adds visit by visit through
    // add_to_node, so that neighbouring lanes whose corners fall in the same cell sum their
    // values before the atomic (sorted points share most of them).
    // only_scatter_of_kernel: the kernel stages no other record, so its shared array is
    // sized to this one. MUSL's remap (3D GIMP: 14 values, 14 KB a block against 34 KB):
    // shared memory had held it to 6 blocks per SM where its registers allow 7; P1's remap
    // went from 2.93 to 2.65 ms at 12.8M points (H100, doc/performance.md).
    template <int dim, typename Shape, bool only_scatter_of_kernel = false, int K, int Kg, typename Real>
    MPM_HOST_DEVICE static void scatter_stencil(const GridView<dim, Real> &g, const Real x[dim], const Real lp[dim],
                                                Real *const *targets, const StencilContribution<dim, K, Kg, Real> &c)
    {
      if constexpr (Shape::tensor_product)
        scatter_tensor_stencil<dim, Shape, only_scatter_of_kernel>(g, x, lp, targets, c);
      else
        for_each_stencil_node<dim, Shape>(g, x, lp, [&](const int node, const Real N, const Real *grad) {
          Real values[K];
          c.values(N, grad, values);
          add_to_node<K>(targets, node, values);
        });
    }

    template <int dim, typename Shape, bool only_scatter_of_kernel, int K, int Kg, typename Real>
    MPM_HOST_DEVICE static void scatter_tensor_stencil(const GridView<dim, Real> &g, const Real x[dim],
                                                       const Real lp[dim], Real *const *targets,
                                                       const StencilContribution<dim, K, Kg, Real> &c)
    {
#if defined(__CUDA_ARCH__)
      using Pair                     = typename cuda_detail::Pair<Real>::type;
      constexpr int      n           = Shape::n_per_direction;
      constexpr int      n_stencil   = dim == 2 ? n * n : n * n * n;
      constexpr int      n_w         = dim * n;
      constexpr bool     with_grad   = Kg > 0;
      // Record: the 1D weights (w, dw) in pairs (or w alone), then the coefficients
      // c_N[K], c_grad[Kg][dim], read in pairs: every offset even.
      constexpr int      at_c        = with_grad ? 2 * n_w : n_w + n_w % 2;
      constexpr int      n_c         = K + Kg * dim;
      constexpr int      n_c_even    = n_c + n_c % 2;
      constexpr int      stride      = at_c + n_c_even;
      constexpr unsigned all         = 0xffffffffu;
      // A record longer than the staging area (the cubic B-spline's 4 x 4 x 4 nodes with
      // gradients in 3D) adds point by point too.
      constexpr bool     staged      = stride <= cuda_detail::max_record_values;
      if (!staged || __activemask() != all || blockDim.x > cuda_detail::max_stencil_threads)
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
      stencil_weights<dim, Shape>(g, x, lp, inv_h, first, w, dw);
      long       lattice_stride[dim], base;
      bool       in_lattice = false;
      const bool inside     = stencil_base<dim, n>(g, first, lattice_stride, base, &in_lattice);

      // Runs of neighbouring lanes with the same first stencil node, and the warp's table
      // of them (filled by each run's head); through a block table base is the first
      // node's lattice index, a key all the same.
      const long key = inside || in_lattice ? base : -1 - lane;
      const long     prev   = __shfl_up_sync(all, key, 1);
      const unsigned heads  = __ballot_sync(all, lane == 0 || prev != key);
      const unsigned upto   = all >> (31 - lane);
      const int      head   = 31 - __clz(static_cast<int>(heads & upto));
      const int      n_runs = __popc(heads);
      int *runs = cuda_detail::stencil_runs() + (threadIdx.x & ~31u) * cuda_detail::run_entry_ints;
      if (lane == head)
        {
          const unsigned later = lane == 31 ? 0u : heads & (all << (lane + 1));
          int           *entry = runs + (__popc(heads & upto) - 1) * cuda_detail::run_entry_ints;
          entry[0]             = lane;
          entry[1]             = (later != 0u ? __ffs(static_cast<int>(later)) - 1 : 32) - lane;
          for (int d = 0; d < dim; ++d)
            entry[2 + d] = first[d];
        }

      constexpr int capacity = !only_scatter_of_kernel ? cuda_detail::max_record_values : staged ? stride : 1;
      Real *records = cuda_detail::stencil_records<Real, capacity>() + (threadIdx.x & ~31u) * stride;
      Real *mine    = records + lane * stride;
      for (int d = 0; d < dim; ++d)
        for (int j = 0; j < n; ++j)
          if (with_grad)
            reinterpret_cast<Pair *>(mine)[d * n + j] = Pair{w[d][j], dw[d][j]};
          else
            mine[d * n + j] = w[d][j];
      {
        Real coefficients[n_c_even];
        for (int v = 0; v < K; ++v)
          coefficients[v] = c.c_N[v];
        for (int v = 0; v < Kg; ++v)
          for (int e = 0; e < dim; ++e)
            coefficients[K + v * dim + e] = c.c_grad[v][e];
        if (n_c % 2 == 1)
          coefficients[n_c_even - 1] = Real(0);
        for (int v = 0; v < n_c_even; v += 2)
          reinterpret_cast<Pair *>(mine + at_c)[v / 2] = Pair{coefficients[v], coefficients[v + 1]};
      }
      __syncwarp();

      // Sum over the points of a run (its table entry) of their values at stencil node k.
      auto add_run = [&](const int *entry, const int k[3], Real sum[K]) {
        const int from = entry[0];
        const int to   = from + entry[1];
        for (int l = from; l < to; ++l)
          {
            const Real *record = records + l * stride;
            Real        wk[dim], dwk[dim], grad[dim];
            for (int d = 0; d < dim; ++d)
              if (with_grad)
                {
                  const Pair wp = reinterpret_cast<const Pair *>(record)[d * n + k[d]];
                  wk[d]         = wp.x;
                  dwk[d]        = wp.y;
                }
              else
                {
                  wk[d]  = record[d * n + k[d]];
                  dwk[d] = Real(0);
                }
            const Real N = stencil_weight_at<dim>(wk, dwk, inv_h, grad);
            Real       coefficients[n_c_even];
            for (int v = 0; v < n_c_even; v += 2)
              {
                const Pair cp       = reinterpret_cast<const Pair *>(record + at_c)[v / 2];
                coefficients[v]     = cp.x;
                coefficients[v + 1] = cp.y;
              }
            StencilContribution<dim, K, Kg, Real> point;
            for (int v = 0; v < K; ++v)
              point.c_N[v] = coefficients[v];
            for (int v = 0; v < Kg; ++v)
              for (int e = 0; e < dim; ++e)
                point.c_grad[v][e] = coefficients[K + v * dim + e];
            Real values[K];
            point.values(N, grad, values);
            for (int v = 0; v < K; ++v)
              sum[v] += values[v];
          }
      };
      // The sums of stencil node k of the run with this table entry into the grid; a GIMP
      // weight is exactly zero where a point's domain ends at the node's support (points
      // near their initial sites, lp = h/4), and adding 0 changes nothing.
      auto flush = [&](const int *entry, const int k[3], const Real sum[K]) {
        int idx[dim];
        for (int d = 0; d < dim; ++d)
          idx[d] = entry[2 + d] + k[d];
        const int node = g.node(idx);
        if (node >= 0) // else absent, or outside the lattice where the weight is zero
          for (int v = 0; v < K; ++v)
            if (sum[v] != Real(0))
              atomicAdd(&targets[v][node], sum[v]);
      };

#if !defined(MPM_SCATTER_ROLLING)
#  define MPM_SCATTER_ROLLING 1
#endif
      if constexpr (MPM_SCATTER_ROLLING && dim == 3 && n_stencil > 16 && n_stencil <= 32)
        {
          // 3D GIMP: lane s holds stencil node s while the warp goes through its runs in
          // order. Sorted points come as runs along x (4 runs of 8 per warp in the bulk),
          // and the next run along x shares two of its three node layers with this one: the
          // lanes then pass their sums one node down x (shuffle) and only the layer that
          // leaves sends its sums to the grid. About half the atomics of one per run and
          // node, with the same sums per lane and the same broadcast reads of the records.
          const int  s    = lane;
          const bool mine = s < n_stencil;
          const int  k[3] = {s % n, (s / n) % n, s / (n * n)};
          Real       held[K];
          for (int v = 0; v < K; ++v)
            held[v] = Real(0);
          for (int run = 0; run < n_runs; ++run)
            {
              const int *entry = runs + run * cuda_detail::run_entry_ints;
              if (run > 0)
                {
                  const int *previous = entry - cuda_detail::run_entry_ints;
                  const bool next_along_x =
                    entry[2] == previous[2] + 1 && entry[3] == previous[3] && entry[4] == previous[4];
                  if (mine && (!next_along_x || k[0] == 0))
                    flush(previous, k, held);
                  for (int v = 0; v < K; ++v)
                    {
                      const Real from_next = __shfl_down_sync(all, held[v], 1);
                      held[v]              = next_along_x && k[0] < n - 1 ? from_next : Real(0);
                    }
                }
              if (mine)
                add_run(entry, k, held);
            }
          if (mine)
            flush(runs + (n_runs - 1) * cuda_detail::run_entry_ints, k, held);
        }
      else
        // The warp's tasks (run, stencil node) dealt round robin to its lanes.
        for (int task = lane; task < n_runs * n_stencil; task += 32)
          {
            const int  run   = task / n_stencil;
            const int  s     = task - run * n_stencil;
            const int  k[3]  = {s % n, (s / n) % n, s / (n * n)};
            const int *entry = runs + run * cuda_detail::run_entry_ints;
            Real       sum[K];
            for (int v = 0; v < K; ++v)
              sum[v] = Real(0);
            add_run(entry, k, sum);
            flush(entry, k, sum);
          }
      __syncwarp(); // the records and the run table are reused by the next call
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

    // Real: the precision of the points (the register cap's, above); void: FP64's.
    template <typename Real = void, typename F>
    void gather_points(const int n, F &&f)
    {
#if MPM_GATHER_MIN_BLOCKS_FP64 > 0
      if (n <= 0)
        return;
      using FT = typename std::decay<F>::type;
      constexpr int threads = cuda_detail::gather_block_size;
      begin_timing();
      cuda_detail::gather_kernel_bounded<cuda_detail::gather_min_blocks<Real>(), FT>
        <<<(n + threads - 1) / threads, threads, 0, stream>>>(n, f);
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

    // true: reduce_points leaves its result on the device (last_reduction_on_device) and
    // returns the identity without waiting for the device, so that the host can queue the
    // next launches at once (a step queued behind the last one, DeviceEngine::queue_step).
    bool keep_reductions_on_device = false;

    // Where the last reduction's result is on the device, until the next reduction.
    const void *last_reduction_on_device() const
    {
      return static_cast<const unsigned char *>(scratch) + max_reduce_blocks * max_reduction_bytes;
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
      if (keep_reductions_on_device)
        return identity;
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
    static constexpr size_t max_reduction_bytes = 128; // PointTotals<3, double> is 112

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
      // Whole warps: the lane arithmetic of add_to_node and scatter_stencil assumes
      // lane = threadIdx.x % 32.
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
