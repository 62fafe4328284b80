// Evaluate a point's stencil once and visit each of its nodes with the weight N_i(x_p)
// and gradient grad N_i(x_p). Every P2G and G2P stage goes through this helper.
//
// Two forms of the stencil loop, the same nodes in the same order:
// - on the host (HostStencil): one loop over the stencil positions, the node indices from a
//   base index plus strides, bounds checked once per point;
// - on the device (and on the host with -DMPM_UNROLL_STENCIL): loops nested per direction
//   with compile-time bounds, unrolled, so that the weights stay in registers and every
//   index into them is a constant, the products of the outer directions' weights formed
//   once per row, and, where the whole stencil lies inside the lattice, the node's lattice
//   index the point's base index plus a constant offset. The rolled loop that the device
//   ran until 2026-11-29 read the 1D weights from local memory at run-time indices (20 of
//   the remap's 32-byte sectors per point on P1); unrolled, P1's step is 4% faster on an
//   H200 (doc/performance.md). The products come in another order than stencil_weight_at's,
//   so the device's N and grad N differ from the host's by round-off.
#pragma once

#include <mpm/core/cpdi.h>
#include <mpm/core/shape_functions.h>
#include <mpm/core/views.h>

#include <cmath>
#include <type_traits>

#if defined(__CUDA_ARCH__)
#  define MPM_UNROLL _Pragma("unroll")
#else
#  define MPM_UNROLL
#endif

namespace mpm
{
  // N_i(x_p) and grad N_i(x_p) from the 1D weights wk[d] and derivatives dwk[d] (in cell
  // units; the gradient scaled by inv_h) at the node's stencil position, the products in
  // one fixed order, shared by every form of the loop below and by the CUDA backend's
  // stencil scatter (CudaBackend::scatter_stencil).
  template <int dim, typename Real>
  MPM_HOST_DEVICE inline Real stencil_weight_at(const Real wk[dim], const Real dwk[dim], const Real inv_h,
                                                Real grad[dim])
  {
    Real N = Real(1);
    for (int d = 0; d < dim; ++d)
      N *= wk[d];
    for (int d = 0; d < dim; ++d)
      {
        Real g = dwk[d] * inv_h;
        for (int e = 0; e < dim; ++e)
          if (e != d)
            g *= wk[e];
        grad[d] = g;
      }
    return N;
  }

  // The same for stencil position k of a point's 1D weight tables.
  template <int dim, int n, typename Real>
  MPM_HOST_DEVICE inline Real stencil_weight(const Real (&w)[dim][n], const Real (&dw)[dim][n], const Real inv_h,
                                             const int k[3], Real grad[dim])
  {
    Real wk[dim], dwk[dim];
    for (int d = 0; d < dim; ++d)
      {
        wk[d]  = w[d][k[d]];
        dwk[d] = dw[d][k[d]];
      }
    return stencil_weight_at<dim>(wk, dwk, inv_h, grad);
  }

  // Where every form of the stencil loop starts: for the point at x with the domain half lengths
  // half_length (GIMP's; the linear hats and the B-splines ignore them), the first node of its
  // stencil and the 1D weights and derivatives (cell units) per direction.
  template <int dim, typename Shape, typename Real, int n>
  MPM_HOST_DEVICE inline void stencil_weights(const GridView<dim, Real> &grid, const Real x[dim],
                                              const Real half_length[dim], const Real inv_h, int (&first)[dim],
                                              Real (&w)[dim][n], Real (&dw)[dim][n])
  {
    for (int d = 0; d < dim; ++d)
      stencil_weights_1d<Shape>((x[d] - grid.origin[d]) * inv_h, half_length[d] * inv_h, grid.n_cells[d], first[d], w[d],
                                dw[d]);
  }

  // Strides (x fastest, as GridView::node) and the index of the stencil's first node in the
  // grid's box (GridView::node_in_box); returns whether the whole stencil of n nodes per
  // direction lies inside the box (then the node of stencil offset o is
  // grid.node_at(base + o), with no bounds check per node). Through a block table a
  // stencil's nodes are not one index plus offsets: false, and the callers ask
  // GridView::node per node; base is then the lattice index, and *in_lattice (where given)
  // whether the stencil lies inside the lattice (elsewhere: inside the box).
  template <int dim, int n, typename Real>
  MPM_HOST_DEVICE inline bool stencil_base(const GridView<dim, Real> &grid, const int first[dim], long stride[dim],
                                           long &base, bool *in_lattice = nullptr)
  {
    bool inside = true;
    base        = 0;
    if (grid.lattice_to_node != nullptr && grid.block_cells > 0)
      {
        for (int d = 0; d < dim; ++d)
          {
            stride[d] = d == 0 ? 1 : stride[d - 1] * (grid.n_cells[d - 1] + 1);
            base += first[d] * stride[d];
            inside = inside && first[d] >= 0 && first[d] + n - 1 <= grid.n_cells[d];
          }
        if (in_lattice != nullptr)
          *in_lattice = inside;
        return false;
      }
    for (int d = 0; d < dim; ++d)
      {
        stride[d]      = d == 0 ? 1 : stride[d - 1] * grid.box_nodes[d - 1];
        const int from = first[d] - grid.box_lower[d];
        base += from * stride[d];
        inside = inside && from >= 0 && from + n <= grid.box_nodes[d];
      }
    if (in_lattice != nullptr)
      *in_lattice = inside;
    return inside;
  }

  // A stencil's nodes from its 1D weights, each with N, grad N and the node's offset from the
  // point, r = x_i - x_p, as visit(node, N, grad, r): the affine transfers' momentum and APIC's
  // B_p read it (step.h). Used by HostStencil::for_each_with_offset and
  // for_each_stencil_node_with_offset.
  template <int dim, int n, typename Real, typename Visitor>
  MPM_HOST_DEVICE inline void visit_stencil_with_offset(const GridView<dim, Real> &grid, const int (&first)[dim],
                                                        const Real (&w)[dim][n], const Real (&dw)[dim][n],
                                                        const Real inv_h, const Real x[dim], Visitor &&visit)
  {
    constexpr int n_stencil = dim == 2 ? n * n : n * n * n;
    for (int s = 0; s < n_stencil; ++s)
      {
        const int k[3] = {s % n, (s / n) % n, s / (n * n)};
        int       idx[dim];
        Real      offset[dim];
        for (int d = 0; d < dim; ++d)
          {
            idx[d]    = first[d] + k[d];
            offset[d] = grid.origin[d] + grid.h * idx[d] - x[d];
          }
        const int node = grid.node(idx);
        if (node < 0)
          continue; // outside the lattice: the weight is zero for points inside the grid
        Real       grad[dim];
        const Real N = stencil_weight<dim, n>(w, dw, inv_h, k, grad);
        visit(node, N, static_cast<const Real *>(grad), static_cast<const Real *>(offset));
      }
  }

#if !defined(__CUDA_ARCH__)
  // Host: one point's stencil, its 1D weights evaluated once (bit for bit as
  // for_each_stencil_node's), visited as often as a stage needs (G2P velocity and the
  // MUSL remap share one). The node's lattice index is the point's base index plus a
  // constant offset per stencil position; where the whole stencil lies inside the lattice
  // (nearly every point) the bounds are checked once per point, else per node as
  // GridView::node does. Same nodes, same order, same arithmetic for N and grad as the
  // device form.
  // (tensor_product: chosen from the shape; CPDI and CPDI2q use the specialisation below.)
  template <int dim, typename Shape, typename Real, bool tensor_product = Shape::tensor_product>
  struct HostStencil
  {
    static constexpr int n = Shape::n_per_direction;
    int                  first[dim];
    Real                 w[dim][n], dw[dim][n];
    Real                 inv_h;

    HostStencil() = default;
    HostStencil(const GridView<dim, Real> &grid, const Real x[dim], const Real half_length[dim])
      : inv_h(Real(1) / grid.h)
    {
      stencil_weights<dim, Shape>(grid, x, half_length, inv_h, first, w, dw);
    }

    template <typename Visitor>
    void for_each(const GridView<dim, Real> &grid, Visitor &&visit) const
    {
      constexpr int n_stencil = dim == 2 ? n * n : n * n * n;
      long          stride[dim], base;
      const bool    inside = stencil_base<dim, n>(grid, first, stride, base);
      auto visit_position = [&](const int s, const int node) {
        const int  k[3] = {s % n, (s / n) % n, s / (n * n)};
        Real       grad[dim];
        const Real N = stencil_weight<dim, n>(w, dw, inv_h, k, grad);
        visit(node, N, grad);
      };
      if (inside)
        {
          for (int s = 0; s < n_stencil; ++s)
            {
              const int k[3]   = {s % n, (s / n) % n, s / (n * n)};
              long      offset = 0;
              for (int d = 0; d < dim; ++d)
                offset += k[d] * stride[d];
              const int node = grid.node_at(base + offset);
              if (node >= 0) // absent from this rank's node set
                visit_position(s, node);
            }
        }
      else
        for (int s = 0; s < n_stencil; ++s)
          {
            const int k[3] = {s % n, (s / n) % n, s / (n * n)};
            int       idx[dim];
            for (int d = 0; d < dim; ++d)
              idx[d] = first[d] + k[d];
            const int node = grid.node(idx);
            if (node >= 0) // else outside the lattice: the weight is zero for points inside the grid
              visit_position(s, node);
          }
    }

    // The same nodes and weights with each node's offset from the point, x_i - x_p, as
    // visit(node, N, grad, offset): APIC's affine transfers (step.h) need it.
    template <typename Visitor>
    void for_each_with_offset(const GridView<dim, Real> &grid, const Real x[dim], Visitor &&visit) const
    {
      visit_stencil_with_offset<dim, n>(grid, first, w, dw, inv_h, x, visit);
    }
  };

  // CPDI and CPDI2q: the point's position and domain, the corners' weights evaluated on each visit.
  template <int dim, typename Shape, typename Real>
  struct HostStencil<dim, Shape, Real, false>
  {
    static constexpr int n_domain = domain_values<dim, Shape>();
    Real                 x[dim], domain[n_domain];

    HostStencil() = default;
    HostStencil(const GridView<dim, Real> &, const Real x_p[dim], const Real domain_p[])
    {
      for (int d = 0; d < dim; ++d)
        x[d] = x_p[d];
      for (int k = 0; k < n_domain; ++k)
        domain[k] = domain_p[k];
    }

    template <typename Visitor>
    void for_each(const GridView<dim, Real> &grid, Visitor &&visit) const
    {
      visit_domain_stencil<dim, Shape>(
        grid, x, domain, [&](const int node, const Real N, const Real *grad, const Real *) { visit(node, N, grad); });
    }
    template <typename Visitor>
    void for_each_with_offset(const GridView<dim, Real> &grid, const Real *, Visitor &&visit) const
    {
      visit_domain_stencil<dim, Shape>(grid, x, domain, visit);
    }
  };
#endif

  template <int dim, typename Shape, typename Real, typename Visitor>
  MPM_HOST_DEVICE inline void for_each_stencil_node(const GridView<dim, Real> &grid,
                                                    const Real x[dim],
                                                    const Real half_length[dim],
                                                    Visitor  &&visit)
  {
    if constexpr (!Shape::tensor_product) // CPDI: half_length is the domain (cpdi.h)
      {
        visit_domain_stencil<dim, Shape>(grid, x, half_length,
                                [&](const int node, const Real N, const Real *grad, const Real *) {
                                  visit(node, N, grad);
                                });
        return;
      }
    else
      {
#if !defined(MPM_UNROLL_STENCIL) && !defined(__CUDA_ARCH__)
    HostStencil<dim, Shape, Real>(grid, x, half_length).for_each(grid, visit);
#else
    constexpr int n = Shape::n_per_direction;
    int           first[dim];
    Real          w[dim][n], dw[dim][n];
    const Real    inv_h = Real(1) / grid.h;
    stencil_weights<dim, Shape>(grid, x, half_length, inv_h, first, w, dw);

    long       stride[dim], base;
    const bool inside = stencil_base<dim, n>(grid, first, stride, base);
    // Node of stencil position k: by offset inside the lattice, else checked per node
    // (-1 outside the lattice, where the weight is zero for points inside the grid).
    auto node_at = [&](const int k[dim]) {
      if (inside)
        {
          long offset = 0;
          for (int d = 0; d < dim; ++d)
            offset += k[d] * stride[d];
          return grid.node_at(base + offset);
        }
      int idx[dim];
      for (int d = 0; d < dim; ++d)
        idx[d] = first[d] + k[d];
      return grid.node(idx);
    };
    for (int d = 0; d < dim; ++d)
      for (int k = 0; k < n; ++k)
        dw[d][k] *= inv_h;

    // checked: each node looked up and skipped where absent. Unchecked where the lattice is
    // dense (no node table) and the whole stencil inside it, as for nearly every point: every
    // node is base + offset and none is skipped, so the unrolled loop has no branch per node
    // and the loads of a gather over all its nodes can be in flight together (behind a
    // branch each had to wait for the one before). The same nodes, order and arithmetic.
    auto visit_nodes = [&](auto checked) {
      auto node_of = [&](const int k[dim]) {
        if constexpr (decltype(checked)::value)
          return node_at(k);
        else
          {
            long offset = 0;
            for (int d = 0; d < dim; ++d)
              offset += k[d] * stride[d];
            return static_cast<int>(base + offset);
          }
      };
      if constexpr (dim == 3)
        {
          MPM_UNROLL
          for (int kz = 0; kz < n; ++kz)
            MPM_UNROLL
            for (int ky = 0; ky < n; ++ky)
              {
                const Real w_yz = w[1][ky] * w[2][kz], dw_y = dw[1][ky] * w[2][kz], dw_z = w[1][ky] * dw[2][kz];
                MPM_UNROLL
                for (int kx = 0; kx < n; ++kx)
                  {
                    const int k[3] = {kx, ky, kz};
                    const int node = node_of(k);
                    if (decltype(checked)::value && node < 0)
                      continue;
                    const Real grad[3] = {dw[0][kx] * w_yz, w[0][kx] * dw_y, w[0][kx] * dw_z};
                    visit(node, w[0][kx] * w_yz, grad);
                  }
              }
        }
      else
        {
          MPM_UNROLL
          for (int ky = 0; ky < n; ++ky)
            MPM_UNROLL
            for (int kx = 0; kx < n; ++kx)
              {
                const int k[2] = {kx, ky};
                const int node = node_of(k);
                if (decltype(checked)::value && node < 0)
                  continue;
                const Real grad[2] = {dw[0][kx] * w[1][ky], w[0][kx] * dw[1][ky]};
                visit(node, w[0][kx] * w[1][ky], grad);
              }
        }
    };
    if (inside && grid.lattice_to_node == nullptr)
      visit_nodes(std::false_type());
    else
      visit_nodes(std::true_type());
#endif
      }
  }

  // The same nodes, weights and gradients as for_each_stencil_node, each with the node's offset
  // from the point, r = x_i - x_p: visit(node, N, grad, r). The affine transfers' momentum and
  // APIC's B_p read it (step.h); host and device, the offsets computed as HostStencil's.
  template <int dim, typename Shape, typename Real, typename Visitor>
  MPM_HOST_DEVICE inline void for_each_stencil_node_with_offset(const GridView<dim, Real> &grid, const Real x[dim],
                                                                const Real half_length[dim], Visitor &&visit)
  {
    if constexpr (!Shape::tensor_product)
      visit_domain_stencil<dim, Shape>(grid, x, half_length, visit);
    else
      {
        constexpr int n = Shape::n_per_direction;
        int           first[dim];
        Real          w[dim][n], dw[dim][n];
        const Real    inv_h = Real(1) / grid.h;
        stencil_weights<dim, Shape>(grid, x, half_length, inv_h, first, w, dw);
        visit_stencil_with_offset<dim, n>(grid, first, w, dw, inv_h, x, visit);
      }
  }
} // namespace mpm

#undef MPM_UNROLL
