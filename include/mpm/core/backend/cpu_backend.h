// CPU backend: how the step's loops run on the host.
// Node loops and gather loops (each point writes only itself) run in parallel
// through TBB when available. Scatter loops run serially, so plain additions are
// race-free and the sums are deterministic (same order every run).
#pragma once

#include <mpm/core/config.h>

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

    // MPM_HOST_DEVICE only so that nvcc accepts the step's __host__ __device__ lambdas
    // instantiated with this backend in a .cu file; it only ever runs on the host.
    template <typename T>
    MPM_HOST_DEVICE static void add(T *target, const T value)
    {
      *target += value;
    }

    template <typename F>
    void for_each_node(const int n, F &&f) const
    {
      parallel(n, f);
    }

    template <typename F>
    void gather_points(const int n, F &&f) const
    {
      parallel(n, f);
    }

    template <typename F>
    void scatter_points(const int n, F &&f) const
    {
      for (int i = 0; i < n; ++i)
        f(i);
    }

    template <typename T, typename F, typename Combine>
    T reduce_points(const int n, const T identity, F &&f, Combine &&combine) const
    {
#ifdef MPM_WITH_TBB
      if (n > grain)
        return tbb::parallel_reduce(
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
    static constexpr int grain = 2048;

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
