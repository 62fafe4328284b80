// CPU backend: how the step's loops run on the host.
// Node loops and gather loops (each point writes only itself) run in parallel
// through TBB when available. Scatter loops run in parallel by colouring:
//
//   The step hands the backend (group_points, before the scatters of every point
//   configuration) each point's key: the lattice index k along one axis at which its
//   scatter stencil starts; a point's scatter then writes only entries whose lattice
//   index along that axis lies in [k, k + span - 1]. Points are binned into slabs of
//   W = span + 1 lattice layers by the key they had when the slabs were built.
//
//   Margin. A grouping is kept for later point configurations as long as every point's
//   key is still within one layer of its slab: k in [b W - 1, b W + W]. Slab b then
//   writes only layers [b W - 1, b W + W + span - 1] and slab b + 2 only from
//   (b + 2) W - 1 = b W + W + span on: slabs b and b + 2 never touch the same entry.
//   All even slabs run in parallel, then all odd slabs: plain additions, no atomics.
//
//   Why the grouping lasts several steps (CFL 0.5): dt <= 0.5 h / (c + max |v_p|), and a
//   point moves by dt times a weighted mean of nodal velocities per step, less than half a
//   cell, and in the collapse much less (|v| of 1-2 m/s against c of 21 m/s: about 0.05
//   cells per step). Its key changes by one layer on a crossing, so a point must travel
//   more than about a cell before it leaves its slab's margin: about 20 steps and more.
//   Fail-safe: nothing relies on that estimate. group_points checks every point's
//   current key against its slab (one parallel pass, no writes) before each point
//   configuration's scatters and rebuilds the grouping when a single point is outside
//   the margin, when the number of points, layers or span changed, or when a removed
//   point (key < 0 when grouped) is alive again. The step calls group_points again after
//   the points move within a step (before pressure averaging), and marks the grouping
//   unchecked (ungroup) at the end of the step, so a scatter outside a checked
//   configuration runs serially.
//
// Within a slab the points run in index order and the slabs of one colour write
// disjoint entries, so every sum is formed in the same order on every run and for
// any number of threads: results are deterministic (though not bit-identical with
// the serial order). Removed points (key < 0) are left out when the slabs are built,
// so scatters do no work for them; points removed later stay in their slab, and their
// scatters write nothing (the step skips them). Without a checked grouping (or without
// TBB) a scatter runs serially over all points.
#pragma once

#include <mpm/core/config.h>
#include <mpm/core/interpolation.h>
#include <mpm/core/stencil_contribution.h>

#include <cstddef>
#include <vector>

#ifdef MPM_WITH_TBB
#  include <tbb/blocked_range.h>
#  include <tbb/parallel_for.h>
#  include <tbb/parallel_reduce.h>
#endif

namespace mpm
{
  struct CpuBackend
  {
    static constexpr const char *name = "cpu";

    // The step calls group_points before scatters (see step.h, group_for_scatter).
    static constexpr bool colours_scatter = true;

    // Scatter adds (step.h): targets[k][entry] += values[k] for k < K. A plain +=: the
    // colouring keeps concurrent slabs apart. MPM_HOST_DEVICE only so that nvcc accepts
    // the step's __host__ __device__ lambdas instantiated with this backend in a .cu file;
    // it only ever runs on the host.
    template <int K, typename T>
    MPM_HOST_DEVICE static void add_to_node(T *const *targets, const int entry, const T *values)
    {
      for (int k = 0; k < K; ++k)
        targets[k][entry] += values[k];
    }

    // A point's contribution into each node of its stencil (step.h: device code and the
    // -DMPM_UNROLL_STENCIL build; the default host stages use the point's HostStencil
    // with add_contribution directly). only_scatter_of_kernel: the CUDA backend's sizing
    // of its shared records (cuda_backend.h); nothing to size here.
    template <int dim, typename Shape, bool only_scatter_of_kernel = false, int K, int Kg, typename Real>
    MPM_HOST_DEVICE static void scatter_stencil(const GridView<dim, Real> &g, const Real x[dim], const Real lp[dim],
                                                Real *const *targets, const StencilContribution<dim, K, Kg, Real> &c)
    {
      add_contribution<CpuBackend>([&](auto &&visit) { for_each_stencil_node<dim, Shape>(g, x, lp, visit); }, targets,
                                   c);
    }

    template <typename F>
    void for_each_node(const int n, F &&f) const
    {
      parallel(n, f);
    }

    template <typename Real = void, typename F> // Real: as CudaBackend's (its register cap)
    void gather_points(const int n, F &&f) const
    {
      parallel(n, f);
    }

    // Groups points 0..n-1 for the coming scatters: key(i) is the first lattice index
    // (along the colouring axis, 0 <= key < n_layers) that point i's scatter writes,
    // and the point writes at most `span` consecutive layers from there; key(i) < 0:
    // the point writes nothing (removed). Keeps the current slabs where every point is
    // still inside their margin (see the top of this file), else builds them again.
    // key must be safe to call concurrently. Valid until the points move: the step
    // calls this again after they moved, and ungroup() at the end of the step.
    template <typename Key>
    void group_points(const int n, const int n_layers, const int span, Key &&key)
    {
      checked = false;
      if (grouped_points == n && grouped_layers == n_layers && grouped_span == span)
        {
          const int   W        = span + 1;
          const int  *slab     = slab_of.data();
          const bool  in_slabs = reduce_points(
            n, true,
            [&](const int i) {
              const int k = key(i);
              if (k < 0)
                return true; // writes nothing
              const int c = k >= n_layers ? n_layers - 1 : k;
              const int b = slab[i];
              return b >= 0 && c >= b * W - 1 && c <= b * W + W;
            },
            [](const bool a, const bool b) { return a && b; });
          if (in_slabs)
            {
              checked = true;
              ++n_reused;
              return;
            }
        }
      const int W       = span + 1;
      const int n_slabs = (n_layers + W - 1) / W;
      slab_of.resize(n);
      slab_start.assign(n_slabs + 1, 0);
      for (int i = 0; i < n; ++i)
        {
          const int k = key(i);
          slab_of[i]  = k < 0 ? -1 : (k >= n_layers ? n_layers - 1 : k) / W;
          if (slab_of[i] >= 0)
            ++slab_start[slab_of[i] + 1];
        }
      for (int b = 0; b < n_slabs; ++b)
        slab_start[b + 1] += slab_start[b];
      order.resize(slab_start[n_slabs]);
      fill.assign(slab_start.begin(), slab_start.end() - 1);
      for (int i = 0; i < n; ++i)
        if (slab_of[i] >= 0)
          order[fill[slab_of[i]]++] = i;
      for (int colour = 0; colour < 2; ++colour)
        occupied_slabs[colour].clear();
      for (int b = 0; b < n_slabs; ++b)
        if (slab_start[b + 1] > slab_start[b])
          occupied_slabs[b % 2].push_back(b);
      grouped_points = n;
      grouped_layers = n_layers;
      grouped_span   = span;
      checked        = true;
      ++n_built;
    }

    // The points are about to move: scatters run serially until group_points has
    // checked (or rebuilt) the grouping for the new configuration.
    void ungroup() { checked = false; }

    // Forgets the slabs altogether (the next group_points builds them).
    void forget_grouping()
    {
      checked        = false;
      grouped_points = -1;
    }

    // Scratch memory for n points of `bytes` each (8-byte aligned), kept between calls so
    // that the step allocates nothing once it has run (step.h: P2G keeps the points'
    // stencils there for the remap and the kinematics of the same step).
    void *point_scratch(const std::size_t n, const std::size_t bytes)
    {
      const std::size_t words = (n * bytes + sizeof(double) - 1) / sizeof(double);
      if (scratch.size() < words)
        scratch.resize(words);
      return scratch.data();
    }

    // How often group_points built the slabs and how often it kept them (for benchmarks).
    long n_built = 0, n_reused = 0;

    template <typename F>
    void scatter_points(const int n, F &&f) const
    {
#ifdef MPM_WITH_TBB
      if (checked && grouped_points == n && n > grain)
        {
          for (int colour = 0; colour < 2; ++colour)
            {
              const std::vector<int> &slabs = occupied_slabs[colour];
              tbb::parallel_for(tbb::blocked_range<int>(0, static_cast<int>(slabs.size()), 1),
                                [&](const tbb::blocked_range<int> &r) {
                                  for (int s = r.begin(); s < r.end(); ++s)
                                    for (int j = slab_start[slabs[s]]; j < slab_start[slabs[s] + 1]; ++j)
                                      f(order[j]);
                                });
            }
          return;
        }
#endif
      for (int i = 0; i < n; ++i)
        f(i);
    }

    template <typename T, typename F, typename Combine>
    T reduce_points(const int n, const T identity, F &&f, Combine &&combine) const
    {
#ifdef MPM_WITH_TBB
      // Deterministic: the same chunks combined in the same tree on any run and thread count, so
      // that sums (the history's mass, energy, momentum) repeat to the last bit.
      if (n > grain)
        return tbb::parallel_deterministic_reduce(
          tbb::blocked_range<int>(0, n, grain), identity,
          [&](const tbb::blocked_range<int> &r, T acc) {
            for (int i = r.begin(); i < r.end(); ++i)
              acc = combine(acc, f(i));
            return acc;
          },
          combine);
#endif
      T acc = identity;
      for (int i = 0; i < n; ++i)
        acc = combine(acc, f(i));
      return acc;
    }

    void synchronize() const {}

  private:
    // Points or nodes per TBB chunk. 512 rather than 2048: 25 chunks instead of 6-7 for the
    // 12,800 points of V3 balance two threads better (core bench, 2 threads, quiet machine:
    // 1.90 s against 2.10 s wall per 1000 steps, mean of 5 alternating runs).
    static constexpr int grain = 512;

    // Grouping for the coloured scatter: points of slab b are order[slab_start[b] ..
    // slab_start[b + 1]), in index order; slab_of[i] is point i's slab (-1: left out).
    int              grouped_points = -1, grouped_layers = -1, grouped_span = -1;
    bool             checked        = false; // the slabs hold for the current point configuration
    std::vector<int> slab_of, slab_start, fill, order;
    // The even and the odd slabs that hold points: the scatters' parallel loops run over
    // these only. Over every slab of the lattice, a box much longer than the material
    // left TBB's first split of the range with all the work on one side, so that one thread
    // did nearly all of it (P2 in a box 4x longer, 2 threads: 1.7x against 1.9x in its own
    // box, doc/performance.md).
    std::vector<int>    occupied_slabs[2];
    std::vector<double> scratch; // point_scratch

    template <typename F>
    static void parallel(const int n, F &f)
    {
#ifdef MPM_WITH_TBB
      if (n > grain)
        {
          tbb::parallel_for(tbb::blocked_range<int>(0, n, grain), [&](const tbb::blocked_range<int> &r) {
            for (int i = r.begin(); i < r.end(); ++i)
              f(i);
          });
          return;
        }
#endif
      for (int i = 0; i < n; ++i)
        f(i);
    }
  };
} // namespace mpm
