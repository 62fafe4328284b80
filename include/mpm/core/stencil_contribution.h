// What one point adds into each node of its stencil in a scatter (P2G, the MUSL remap),
// written as coefficients of the node's shape function value N and gradient grad N:
//   value[k] = c_N[k] N                                      for k <  K - Kg,
//   value[k] = c_N[k] N + sum_e c_grad[k - K + Kg][e] grad_e  for k >= K - Kg.
// The point's state enters only through the coefficients. A backend can therefore hand
// them to other threads, which sum a stencil node over several points
// (CudaBackend::scatter_stencil), instead of one thread per point adding into all its
// nodes (add_contribution below, the CPU's way).
#pragma once

#include <mpm/core/config.h>

namespace mpm
{
  template <int dim, int K, int Kg, typename Real>
  struct StencilContribution
  {
    static_assert(Kg >= 0 && Kg <= K, "the rows with gradient terms are the last Kg of the K values");
    static constexpr int n_values        = K;
    static constexpr int n_with_gradient = Kg;

    Real c_N[K];
    Real c_grad[Kg > 0 ? Kg : 1][dim];

    MPM_HOST_DEVICE void values(const Real N, const Real *grad, Real out[K]) const
    {
      for (int k = 0; k < K; ++k)
        out[k] = c_N[k] * N;
      for (int k = 0; k < Kg; ++k)
        for (int e = 0; e < dim; ++e)
          out[K - Kg + k] += c_grad[k][e] * grad[e];
    }
  };

  // One thread adds a point's contribution into each node its stencil visits:
  // stencil(visit) calls visit(node, N, grad) per node (for_each_stencil_node, or a
  // HostStencil's for_each); targets[k][node] += value[k] through Backend::add_to_node.
  template <typename Backend, int dim, int K, int Kg, typename Real, typename Stencil>
  MPM_HOST_DEVICE inline void add_contribution(Stencil &&stencil, Real *const *targets,
                                               const StencilContribution<dim, K, Kg, Real> &c)
  {
    stencil([&](const int n, const Real N, const Real *grad) {
      Real values[K];
      c.values(N, grad, values);
      Backend::template add_to_node<K>(targets, n, values);
    });
  }
} // namespace mpm
