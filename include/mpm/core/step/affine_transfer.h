// The affine transfers (APIC, TPIC): the affine matrix C_p from the nodal velocities and its
// momentum m N_i C_p (x_i - x_p) in P2G.
// Part of the explicit step (step.h); header-only, host and device.
#pragma once

#include <cmath>
#include <mpm/core/cubic_bspline_gimp.h>
#include <mpm/core/domain_update.h>
#include <mpm/core/interpolation.h>
#include <mpm/core/local_damping.h>
#include <mpm/core/material/material.h>
#include <mpm/core/prefetch.h>
#include <mpm/core/shape_functions.h>
#include <mpm/core/small_tensor.h>
#include <mpm/core/stencil_contribution.h>
#include <mpm/core/step/backend_traits.h>
#include <mpm/core/step/point_domain.h>
#include <mpm/core/step/settings.h>
#include <mpm/core/views.h>
#include <mpm/core/wall_friction.h>
#include <stdexcept>
#include <type_traits>
#include <utility>

#include <cmath>
#include <stdexcept>
#include <type_traits>
#include <utility>

namespace mpm
{
  namespace stages
  {
    // APIC's D_p / h^2 for a shape function (Jiang et al. 2015), 0 where it has none constant.
    template <typename Shape>
    MPM_HOST_DEVICE constexpr double apic_inertia_over_h2()
    {
      return Shape::apic_inertia_over_h2;
    }

    // A point's stencil visited with the weights evaluated on each visit (the device's form,
    // for_each_stencil_node), with the interface of HostStencil that the affine transfers use.
    template <int dim, typename Shape, typename Real>
    struct PointStencil
    {
      const Real *x, *half_length;
      template <typename Visitor>
      MPM_HOST_DEVICE void for_each(const GridView<dim, Real> &g, Visitor &&visit) const
      {
        for_each_stencil_node<dim, Shape>(g, x, half_length, visit);
      }
      template <typename Visitor>
      MPM_HOST_DEVICE void for_each_with_offset(const GridView<dim, Real> &g, const Real *, Visitor &&visit) const
      {
        for_each_stencil_node_with_offset<dim, Shape>(g, x, half_length, visit);
      }
    };

    // The affine matrix of a point from the nodal velocities v_i (`nodal`).
    // TPIC, the gradient form C = sum_i v_i grad N_i^T: exact for affine fields v = A x + b
    // wherever the weights reproduce linear fields (sum (A x_i + b) grad N_i^T = A), any shape.
    // APIC, C = B_p D_p^-1 with B_p = sum_i N_i v_i (x_i - x_p)^T and the B-splines' constant D_p:
    // exact for affine fields where sum_i N_i r_i r_i^T = D_p, i.e. away from the grid's faces
    // (there the folded weights give a smaller sum, and C is damped towards 0, never amplified).
    // A D_p computed from each stencil instead turns nearly singular at the faces (the V3
    // collapse blew up at 0.48 s with it, doc/log.md). Linear weights: APIC's B D^-1 is the
    // gradient form (Jiang et al.), which is what is computed. Stencil: HostStencil on the
    // host, PointStencil on the device.
    template <int dim, typename Shape, typename Real, typename Stencil>
    MPM_HOST_DEVICE inline void affine_matrix_of(const GridView<dim, Real> &g, Real *const *nodal,
                                                 const Stencil &stencil, const Real x[dim], const AffineMatrix form,
                                                 Real C[dim * dim])
    {
      for (int k = 0; k < dim * dim; ++k)
        C[k] = Real(0);
      constexpr double inertia = apic_inertia_over_h2<Shape>();
      if (form == AffineMatrix::b_d_inverse && inertia > 0)
        {
          const Real scale = Real(1) / (Real(inertia) * g.h * g.h);
          stencil.for_each_with_offset(g, x, [&](const int n, const Real N, const Real *, const Real *r) {
            for (int a = 0; a < dim; ++a)
              for (int b = 0; b < dim; ++b)
                C[a * dim + b] += scale * N * nodal[a][n] * r[b];
          });
          return;
        }
      stencil.for_each(g, [&](const int n, const Real, const Real *grad) {
        for (int a = 0; a < dim; ++a)
          for (int b = 0; b < dim; ++b)
            C[a * dim + b] += nodal[a][n] * grad[b];
      });
    }

    // The affine part of a point's momentum into its stencil: m N_i C (x_i - x_p). Host
    // backends add it in P2G's own loop; atomic ones (the device) in a pass of its own
    // (add_affine_momentum below), since add_to_node's staging area does not fit beside
    // scatter_stencil's shared records in one kernel, and one atomicAdd per value instead
    // cost TPIC's step 2.6x the blend's on P1 (doc/log.md).
    template <typename Backend, int dim, typename Real, typename Stencil>
    MPM_HOST_DEVICE inline void add_apic_momentum(const GridView<dim, Real> &g, const Stencil &stencil,
                                                  const Real x[dim], const Real m, const Real C[dim * dim])
    {
      Real *targets[dim];
      for (int d = 0; d < dim; ++d)
        targets[d] = g.momentum[d];
      stencil.for_each_with_offset(g, x, [&](const int n, const Real N, const Real *, const Real *r) {
        Real values[dim];
        for (int a = 0; a < dim; ++a)
          {
            Real cr = Real(0);
            for (int b = 0; b < dim; ++b)
              cr += C[a * dim + b] * r[b];
            values[a] = m * N * cr;
          }
        Backend::template add_to_node<dim>(targets, n, values);
      });
    }

    template <int dim, typename Real>
    MPM_HOST_DEVICE inline void load_affine(const PointsView<dim, Real> &p, const StepSettings<dim, Real> &s,
                                            const int i, Real C[dim * dim])
    {
      for (int k = 0; k < dim * dim; ++k)
        C[k] = p.state_variables[s.affine_state_variable + k][i];
    }

    template <int dim, typename Real>
    MPM_HOST_DEVICE inline void store_affine(const PointsView<dim, Real> &p, const StepSettings<dim, Real> &s,
                                             const int i, const Real C[dim * dim])
    {
      for (int k = 0; k < dim * dim; ++k)
        p.state_variables[s.affine_state_variable + k][i] = C[k];
    }

    // The affine part of every point's momentum, m N_i C_p (x_i - x_p), in a pass of its own:
    // atomic backends (the device), after each P2G of the momentum (explicit_step). Its adds
    // go through add_to_node, summed per warp where neighbouring points share a node.
    template <int dim, typename Shape, typename Real, typename Backend>
    void add_affine_momentum(Backend &backend, const GridView<dim, Real> &g, const PointsView<dim, Real> &p,
                             const StepSettings<dim, Real> &s)
    {
      backend.scatter_points(p.n_points, [=] MPM_HOST_DEVICE(const int i) {
        if (p.material[i] < 0)
          return;
        Real x[dim], lp[domain_values<dim, Shape>()], C[dim * dim];
        for (int d = 0; d < dim; ++d)
          x[d] = p.position[d][i];
        load_domain<dim, Shape>(p, s, i, lp);
        load_affine(p, s, i, C);
        add_apic_momentum<Backend, dim>(g, PointStencil<dim, Shape, Real>{x, lp}, x, p.mass[i], C);
      });
    }
  } // namespace stages
} // namespace mpm
