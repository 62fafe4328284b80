// Evaluate a point's stencil once and visit each of its nodes with the weight N_i(x_p)
// and gradient grad N_i(x_p). Every P2G and G2P stage goes through this helper.
#pragma once

#include <mpm/core/views.h>

#include <cmath>

// -DMPM_UNROLL_STENCIL unrolls the stencil loop on the device, so that w[d][k] and
// dw[d][k] are indexed by compile-time constants and stay in registers (no stack frame
// in P2G, remap and G2P velocity). Off by default: on P1 at 12.8M points (H100) it made
// G2P kinematics 7% faster but the atomic scatters 5-8% slower, 3% slower in all
// (doc/performance.md, "CUDA backend in dealii-mpm"). The host compiler decides itself.
#if defined(__CUDA_ARCH__) && defined(MPM_UNROLL_STENCIL)
#  define MPM_STENCIL_LOOP_PRAGMA _Pragma("unroll")
#else
#  define MPM_STENCIL_LOOP_PRAGMA
#endif

namespace mpm
{
  template <int dim, typename Shape, typename Real, typename Visitor>
  MPM_HOST_DEVICE inline void for_each_stencil_node(const GridView<dim, Real> &grid,
                                                    const Real x[dim],
                                                    const Real half_length[dim],
                                                    Visitor  &&visit)
  {
    constexpr int n = Shape::n_per_direction;
    int           first[dim];
    Real          w[dim][n], dw[dim][n];
    const Real    inv_h = Real(1) / grid.h;
    for (int d = 0; d < dim; ++d)
      Shape::weights_1d((x[d] - grid.origin[d]) * inv_h, half_length[d] * inv_h, first[d], w[d], dw[d]);

    constexpr int n_stencil = dim == 2 ? n * n : n * n * n;
    MPM_STENCIL_LOOP_PRAGMA
    for (int s = 0; s < n_stencil; ++s)
      {
        int k[3] = {s % n, (s / n) % n, s / (n * n)};
        int idx[dim];
        for (int d = 0; d < dim; ++d)
          idx[d] = first[d] + k[d];
        const int node = grid.node(idx);
        if (node < 0)
          continue; // outside the lattice: the weight is zero for points inside the grid

        Real N = Real(1);
        for (int d = 0; d < dim; ++d)
          N *= w[d][k[d]];
        Real grad[dim];
        for (int d = 0; d < dim; ++d)
          {
            Real g = dw[d][k[d]] * inv_h;
            for (int e = 0; e < dim; ++e)
              if (e != d)
                g *= w[e][k[e]];
            grad[d] = g;
          }
        visit(node, N, grad);
      }
  }
} // namespace mpm
