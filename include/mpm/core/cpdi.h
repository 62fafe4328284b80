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

#include <cmath>

namespace mpm
{
  struct CpdiShape
  {
    static constexpr const char *name        = "CPDI";
    static constexpr const char *description = "the linear hats averaged over each point's parallelogram or parallelepiped domain, whose edges follow F, including its rotation and shear";
    static constexpr ShapeOwner  owner       = ShapeOwner::always;
    static constexpr bool   point_domain                    = false;
    // Not a tensor product: a stretched domain reaches any distance (one MPI rank).
    static constexpr double safe_distance_outside_home_cell = 0.5;
    static constexpr bool   apic                            = false;
    static constexpr double apic_inertia_over_h2            = 0;
    static constexpr bool   in_3d                           = true;
    static constexpr bool tensor_product   = false;
    static constexpr bool tracks_corners   = false; // the domain comes from F (R = F R_0)
    static constexpr int  n_per_direction  = 2;     // linear hats at each corner
    static constexpr bool folds_boundary   = false;
    template <int dim>
    static constexpr int domain_values = dim * dim; // R, row-major
  };

  // CPDI2q (Sadeghirad, Brannon & Guilkey 2013), 2D: the domain is a general quadrilateral
  // whose four corners move with the grid's velocity at each corner, x_c += dt sum_i N_i(x_c)
  // v_i, independently of the point; the linear hats are interpolated bilinearly between the
  // corners (the isoparametric map of the quadrilateral) and averaged over it:
  //   S_ip      = sum_c N_i(x_c) (1/V) int Phi_c dV
  //   grad S_ip = sum_c N_i(x_c) (1/V) int grad Phi_c dV,   V = int dV,
  // integrals over the quadrilateral, exact by 2 x 2 Gauss points in the reference square (the
  // integrands are at most quadratic in each reference coordinate). Domain: the corners'
  // offsets from the point, corner c at x_p + q_c, c's bits the signs of the reference
  // coordinates as CPDI's; kept as state variables delta_c = q_c - R_0 s_c (zero at the start,
  // so points made anywhere start with their rectangle).
  struct Cpdi2qShape
  {
    static constexpr const char *name        = "CPDI2q";
    static constexpr const char *description = "2D: the same over a quadrilateral whose four corners move with the grid's velocity";
    static constexpr ShapeOwner  owner       = ShapeOwner::always;
    static constexpr bool   point_domain                    = false;
    static constexpr double safe_distance_outside_home_cell = 0.5;
    static constexpr bool   apic                            = false;
    static constexpr double apic_inertia_over_h2            = 0;
    static constexpr bool   in_3d                           = false;
    static constexpr bool tensor_product   = false;
    static constexpr bool tracks_corners   = true;
    static constexpr int  n_per_direction  = 2;
    static constexpr bool folds_boundary   = false;
    template <int dim>
    static constexpr int domain_values = (1 << dim) * dim; // q_c, corner by corner
  };

  // The number of values that describe a point's domain for a shape: the half-lengths along
  // the axes (dim) for the tensor-product shapes, R row-major (dim x dim) for CPDI, the
  // corners' offsets for CPDI2q.
  template <int dim, typename Shape>
  MPM_HOST_DEVICE constexpr int domain_values()
  {
    if constexpr (Shape::tensor_product)
      return dim;
    else
      return Shape::template domain_values<dim>;
  }

  // R^-T, row-major, of a dim x dim R (row-major). det R = 0 (a point crushed flat) gives NaN:
  // the point's gradients are then not finite, and the run stops with the instability message
  // that names it (the step's speed check), instead of going on without its forces.
  template <int dim, typename Real>
  MPM_HOST_DEVICE inline void inverse_transpose(const Real *R, Real inv_t[dim * dim])
  {
    if constexpr (dim == 2)
      {
        const Real det = R[0] * R[3] - R[1] * R[2];
        const Real s   = det != Real(0) ? Real(1) / det : Real(NAN);
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
        const Real s   = det != Real(0) ? Real(1) / det : Real(NAN);
        for (int k = 0; k < 9; ++k)
          inv_t[k] = cof[k] * s;
      }
  }

  // Corner c's offset from the point along axis d: R s_c (CPDI; bit k of c the sign of edge
  // k: 1 +, 0 -) or the tracked corner's q_c (CPDI2q).
  template <int dim, typename Shape, typename Real>
  MPM_HOST_DEVICE inline Real corner_offset(const Real *domain, const int d, const int c)
  {
    if constexpr (Shape::tracks_corners)
      return domain[c * dim + d];
    else
      {
        Real sum = Real(0);
        for (int k = 0; k < dim; ++k)
          sum += ((c >> k) & 1 ? domain[d * dim + k] : -domain[d * dim + k]);
        return sum;
      }
  }

  // The lattice layers along axis d that point x with the given domain writes: [lo, hi].
  template <int dim, typename Shape, typename Real>
  MPM_HOST_DEVICE inline void cpdi_layers(const Real origin, const Real h, const int n_cells, const Real x,
                                          const Real *domain, const int d, int &lo, int &hi)
  {
    const Real inv_h = Real(1) / h;
    lo               = n_cells;
    hi               = 0;
    for (int c = 0; c < (1 << dim); ++c)
      {
        Real s = (x + corner_offset<dim, Shape>(domain, d, c) - origin) * inv_h;
        s      = s >= Real(0) ? (s > Real(n_cells) ? Real(n_cells) : s) : Real(0); // NaN: 0
        const int first = static_cast<int>(std::floor(s));
        lo              = first < lo ? first : lo;
        hi              = first + 1 > hi ? first + 1 : hi;
      }
  }

  // A corner's nodes: its cell's (the corner moved onto the lattice where it lies outside),
  // with the linear hats' weights; visit(node, N, idx).
  template <int dim, typename Real, typename Grid, typename Visitor>
  MPM_HOST_DEVICE inline void visit_corner_cell(const Grid &grid, const Real xc[dim], Visitor &&visit)
  {
    const Real inv_h = Real(1) / grid.h;
    int        first[dim];
    Real       w[dim][2];
    for (int d = 0; d < dim; ++d)
      {
        Real       dw[2];
        const Real s = (xc[d] - grid.origin[d]) * inv_h;
        // onto the lattice; a NaN corner (a run about to stop) onto its origin, whose weights stay
        // finite while the NaN reaches the values through the corner's factors
        LinearShape::weights_1d(s >= Real(0) ? (s > Real(grid.n_cells[d]) ? Real(grid.n_cells[d]) : s) : Real(0),
                                Real(0), first[d], w[d], dw);
      }
    for (int k = 0; k < (1 << dim); ++k)
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
        if (node >= 0)
          visit(node, N, static_cast<const int *>(idx));
      }
  }

  // Visits (node, S part, grad S part, offset x_i - x_p) corner by corner; a node lies in
  // several corners' cells and is then visited once per corner. Nodes outside the lattice
  // (weight zero) or absent from the grid's node set are skipped.
  template <int dim, typename Real, typename Grid, typename Visitor>
  MPM_HOST_DEVICE inline void visit_cpdi_stencil(const Grid &grid, const Real x[dim], const Real *R, Visitor &&visit)
  {
    constexpr int n_corners = 1 << dim;
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
        Real xc[dim];
        for (int d = 0; d < dim; ++d)
          xc[d] = x[d] + corner_offset<dim, CpdiShape>(R, d, c);
        visit_corner_cell<dim>(grid, xc, [&](const int node, const Real N, const int *idx) {
          Real grad[dim], offset[dim];
          for (int d = 0; d < dim; ++d)
            {
              grad[d]   = N * corner_grad[d];
              offset[d] = grid.origin[d] + grid.h * idx[d] - x[d];
            }
          visit(node, share * N, static_cast<const Real *>(grad), static_cast<const Real *>(offset));
        });
      }
  }

  // CPDI2q's corner factors: wf[c] = (1/V) int Phi_c dV and wg[c] = (1/V) int grad Phi_c dV over
  // the quadrilateral with corner offsets q (corner c at q[2c], q[2c+1]). Returns V. V <= 0 (the
  // quadrilateral folded over) gives NaN factors: the run stops with the instability message that
  // names the point (the step's speed check), instead of going on without its mass.
  template <typename Real>
  MPM_HOST_DEVICE inline Real cpdi2q_corner_factors(const Real q[8], Real wf[4], Real wg[4][2])
  {
    const Real g   = Real(0.57735026918962576451); // 1/sqrt(3)
    Real       V   = Real(0);
    for (int c = 0; c < 4; ++c)
      wf[c] = wg[c][0] = wg[c][1] = Real(0);
    for (int k = 0; k < 4; ++k)
      {
        const Real xi = k & 1 ? g : -g, eta = k & 2 ? g : -g;
        Real       phi[4], d_xi[4], d_eta[4];
        Real       a = 0, b = 0, cc = 0, d = 0; // J = [dx/dxi dx/deta; dy/dxi dy/deta]
        for (int c = 0; c < 4; ++c)
          {
            const Real sx = c & 1 ? Real(1) : Real(-1), sy = c & 2 ? Real(1) : Real(-1);
            phi[c]   = Real(0.25) * (1 + sx * xi) * (1 + sy * eta);
            d_xi[c]  = Real(0.25) * sx * (1 + sy * eta);
            d_eta[c] = Real(0.25) * sy * (1 + sx * xi);
            a += d_xi[c] * q[2 * c];
            b += d_eta[c] * q[2 * c];
            cc += d_xi[c] * q[2 * c + 1];
            d += d_eta[c] * q[2 * c + 1];
          }
        const Real det = a * d - b * cc; // the Gauss weights are 1
        V += det;
        for (int c = 0; c < 4; ++c)
          {
            wf[c] += phi[c] * det;
            // det J J^-T grad_xi Phi_c
            wg[c][0] += d * d_xi[c] - cc * d_eta[c];
            wg[c][1] += -b * d_xi[c] + a * d_eta[c];
          }
      }
    const Real inv_V = V > Real(0) ? Real(1) / V : Real(NAN);
    for (int c = 0; c < 4; ++c)
      {
        wf[c] *= inv_V;
        wg[c][0] *= inv_V;
        wg[c][1] *= inv_V;
      }
    return V;
  }

  // CPDI2q's stencil, corner by corner as visit_cpdi_stencil's: visit(node, S part, grad S part,
  // offset x_i - x_p). 2D.
  template <int dim, typename Real, typename Grid, typename Visitor>
  MPM_HOST_DEVICE inline void visit_cpdi2q_stencil(const Grid &grid, const Real x[dim], const Real *q, Visitor &&visit)
  {
    static_assert(dim == 2, "CPDI2q is two-dimensional");
    Real wf[4], wg[4][2];
    cpdi2q_corner_factors(q, wf, wg);
    for (int c = 0; c < 4; ++c)
      {
        const Real xc[2] = {x[0] + q[2 * c], x[1] + q[2 * c + 1]};
        visit_corner_cell<2>(grid, xc, [&](const int node, const Real N, const int *idx) {
          Real grad[2], offset[2];
          for (int d = 0; d < 2; ++d)
            {
              grad[d]   = N * wg[c][d];
              offset[d] = grid.origin[d] + grid.h * idx[d] - x[d];
            }
          visit(node, wf[c] * N, static_cast<const Real *>(grad), static_cast<const Real *>(offset));
        });
      }
  }

  // Either CPDI's stencil (the shape's domain: R, or the corners' offsets).
  template <int dim, typename Shape, typename Real, typename Grid, typename Visitor>
  MPM_HOST_DEVICE inline void visit_domain_stencil(const Grid &grid, const Real x[dim], const Real *domain,
                                                   Visitor &&visit)
  {
    if constexpr (Shape::tracks_corners)
      {
        if constexpr (dim == 2)
          visit_cpdi2q_stencil<dim>(grid, x, domain, visit);
      }
    else
      visit_cpdi_stencil<dim>(grid, x, domain, visit);
  }
} // namespace mpm
