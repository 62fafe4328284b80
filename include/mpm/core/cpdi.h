// CPDI (convected particle domain interpolation, Sadeghirad et al. 2011): a point's domain is
// the parallelogram (2D) or parallelepiped (3D) x_p + R xi, xi in [-1, 1]^dim, whose edge
// half-vectors, the columns of R, follow the deformation: R = F R_0, R_0 = diag(initial
// half-lengths). The grid's linear hat functions N_i are interpolated multilinearly between
// the domain's 2^dim corners x_c = x_p + R s_c (s_c in {-1, 1}^dim) and averaged over it:
//   S_ip      = 2^-dim sum_c N_i(x_c)
//   grad S_ip = 2^-dim sum_c N_i(x_c) R^-T s_c
// (the mean of the corner interpolant's gradient over the domain: the domain's volume
// 2^dim |det R| cancels). Partition of unity, sum_i S_ip grad = 0 and the reproduction of
// linear fields hold for any R. A corner outside the lattice is moved onto its nearest face,
// so that its weights stay on lattice nodes. Not a tensor product: a point's nodes are its
// corners' cells' nodes, visited corner by corner (a node shared by two corners is visited
// twice, each time with that corner's part; every stage sums linearly in N and grad N).
#pragma once

#include <mpm/core/config.h>
#include <mpm/core/shape_functions.h>

namespace mpm
{
  struct CpdiShape
  {
    static constexpr bool tensor_product   = false;
    static constexpr int  n_per_direction  = 2; // linear hats at each corner
    static constexpr bool folds_boundary   = false;
    template <int dim>
    static constexpr int corners = 1 << dim;
  };

  // The number of values that describe a point's domain for a shape: the half-lengths along
  // the axes (dim) for the tensor-product shapes, R row-major (dim x dim) for CPDI.
  template <int dim, typename Shape>
  MPM_HOST_DEVICE constexpr int domain_values()
  {
    return Shape::tensor_product ? dim : dim * dim;
  }

  // R^-T, row-major, of a dim x dim R (row-major); det R = 0 (a point crushed flat, which
  // the step's checks on det F report) gives zeros, not infinities.
  template <int dim, typename Real>
  MPM_HOST_DEVICE inline void inverse_transpose(const Real *R, Real inv_t[dim * dim])
  {
    if constexpr (dim == 2)
      {
        const Real det = R[0] * R[3] - R[1] * R[2];
        const Real s   = det != Real(0) ? Real(1) / det : Real(0);
        inv_t[0]       = R[3] * s;
        inv_t[1]       = -R[2] * s;
        inv_t[2]       = -R[1] * s;
        inv_t[3]       = R[0] * s;
      }
    else
      {
        // cofactor matrix / det = (R^-1)^T
        Real cof[9];
        cof[0]         = R[4] * R[8] - R[5] * R[7];
        cof[1]         = R[5] * R[6] - R[3] * R[8];
        cof[2]         = R[3] * R[7] - R[4] * R[6];
        cof[3]         = R[2] * R[7] - R[1] * R[8];
        cof[4]         = R[0] * R[8] - R[2] * R[6];
        cof[5]         = R[1] * R[6] - R[0] * R[7];
        cof[6]         = R[1] * R[5] - R[2] * R[4];
        cof[7]         = R[2] * R[3] - R[0] * R[5];
        cof[8]         = R[0] * R[4] - R[1] * R[3];
        const Real det = R[0] * cof[0] + R[1] * cof[1] + R[2] * cof[2];
        const Real s   = det != Real(0) ? Real(1) / det : Real(0);
        for (int k = 0; k < 9; ++k)
          inv_t[k] = cof[k] * s;
      }
  }

  // Corner c's position in cell units along axis d, moved onto the lattice where it lies
  // outside; sign of its k-th edge vector: bit k of c (1: +, 0: -).
  template <int dim, typename Real>
  MPM_HOST_DEVICE inline Real cpdi_corner_in_cells(const Real origin, const Real inv_h, const int n_cells,
                                                   const Real x, const Real *R, const int d, const int c)
  {
    Real xc = x;
    for (int k = 0; k < dim; ++k)
      xc += ((c >> k) & 1 ? R[d * dim + k] : -R[d * dim + k]);
    const Real s = (xc - origin) * inv_h;
    return s < Real(0) ? Real(0) : (s > Real(n_cells) ? Real(n_cells) : s);
  }

  // The lattice layers along axis d that point x with domain R writes: [lo, hi].
  template <int dim, typename Real>
  MPM_HOST_DEVICE inline void cpdi_layers(const Real origin, const Real h, const int n_cells, const Real x,
                                          const Real *R, const int d, int &lo, int &hi)
  {
    const Real inv_h = Real(1) / h;
    lo               = n_cells;
    hi               = 0;
    for (int c = 0; c < (1 << dim); ++c)
      {
        const int first = static_cast<int>(std::floor(cpdi_corner_in_cells<dim>(origin, inv_h, n_cells, x, R, d, c)));
        lo              = first < lo ? first : lo;
        hi              = first + 1 > hi ? first + 1 : hi;
      }
  }

  // Visits (node, S part, grad S part, offset x_i - x_p) corner by corner; a node lies in
  // several corners' cells and is then visited once per corner. Nodes outside the lattice
  // (weight zero) or absent from the grid's node set are skipped.
  template <int dim, typename Real, typename Grid, typename Visitor>
  MPM_HOST_DEVICE inline void visit_cpdi_stencil(const Grid &grid, const Real x[dim], const Real *R, Visitor &&visit)
  {
    constexpr int n_corners = 1 << dim;
    constexpr int n_nodes   = 1 << dim;
    const Real    inv_h     = Real(1) / grid.h;
    const Real    share     = Real(1) / Real(n_corners);
    Real          inv_t[dim * dim];
    inverse_transpose<dim>(R, inv_t);
    for (int c = 0; c < n_corners; ++c)
      {
        Real corner_grad[dim]; // 2^-dim R^-T s_c
        for (int a = 0; a < dim; ++a)
          {
            Real sum = Real(0);
            for (int k = 0; k < dim; ++k)
              sum += ((c >> k) & 1 ? inv_t[a * dim + k] : -inv_t[a * dim + k]);
            corner_grad[a] = share * sum;
          }
        int  first[dim];
        Real w[dim][2];
        for (int d = 0; d < dim; ++d)
          {
            Real dw[2];
            LinearShape::weights_1d(cpdi_corner_in_cells<dim>(grid.origin[d], inv_h, grid.n_cells[d], x[d], R, d, c),
                                    Real(0), first[d], w[d], dw);
          }
        for (int k = 0; k < n_nodes; ++k)
          {
            int  idx[dim];
            Real N = Real(1);
            for (int d = 0; d < dim; ++d)
              {
                const int kd = (k >> d) & 1;
                idx[d]       = first[d] + kd;
                N *= w[d][kd];
              }
            const int node = grid.node(idx);
            if (node < 0)
              continue;
            Real grad[dim], offset[dim];
            for (int d = 0; d < dim; ++d)
              {
                grad[d]   = N * corner_grad[d];
                offset[d] = grid.origin[d] + grid.h * idx[d] - x[d];
              }
            visit(node, share * N, static_cast<const Real *>(grad), static_cast<const Real *>(offset));
          }
      }
  }
} // namespace mpm
