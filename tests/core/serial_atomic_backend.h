// A host backend that takes the step's atomic-scatter paths (those of the device: the
// pressure averaging's cell sums in the kinematics, the affine momentum in a pass of its
// own, the fused step) with every loop run serially in point order. So a test can run
// those paths on the CPU, and two orders of the same adds give the same sums bit for bit.
#pragma once

#include <mpm/core/config.h>
#include <mpm/core/interpolation.h>
#include <mpm/core/stencil_contribution.h>

#include "targets.h"

namespace mpm_test
{
  struct SerialAtomicBackend
  {
    static constexpr const char *name = "serial atomic";
    // Serial: every add is trivially atomic, in any loop.
    static constexpr bool atomic_scatter = true;

    template <int K, typename T>
    MPM_HOST_DEVICE static void add_to_node(T *const *targets, const int entry, const T *values)
    {
      for (int k = 0; k < K; ++k)
        targets[k][entry] += values[k];
    }

    // A point's contribution into its stencil (the -DMPM_UNROLL_STENCIL build's path);
    // only_scatter_of_kernel sizes the CUDA backend's shared records, nothing here.
    template <int dim, typename Shape, bool only_scatter_of_kernel = false, int K, int Kg, typename Real>
    MPM_HOST_DEVICE static void scatter_stencil(const mpm::GridView<dim, Real> &g, const Real x[dim], const Real lp[dim],
                                Real *const *targets, const mpm::StencilContribution<dim, K, Kg, Real> &c)
    {
      mpm::add_contribution<SerialAtomicBackend>(
        [&](auto &&visit) { mpm::for_each_stencil_node<dim, Shape>(g, x, lp, visit); }, targets, c);
    }

    template <typename F>
    void for_each_node(const int n, F &&f) const
    {
      for (int i = 0; i < n; ++i)
        f(i);
    }

    template <typename Real = void, typename F> // Real: as CudaBackend's (its register cap)
    void gather_points(const int n, F &&f) const
    {
      for (int i = 0; i < n; ++i)
        f(i);
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
      T acc = identity;
      for (int i = 0; i < n; ++i)
        acc = combine(acc, f(i));
      return acc;
    }

    void synchronize() const {}
  };

  // A scene on the host (CpuTarget's storage) stepped by the serial atomic backend.
  template <int dim, typename Real>
  struct SerialAtomicTarget : CpuTarget<dim, Real>
  {
    static constexpr const char *name = "serial atomic";
    SerialAtomicBackend          backend; // hides CpuTarget's
    using CpuTarget<dim, Real>::CpuTarget;
  };
} // namespace mpm_test
