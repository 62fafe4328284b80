// G2P: the points' velocities (FLIP/PIC blend), MUSL's remap, and the kinematics (position, strain and
// spin increments, volume, domain) with the constitutive update.
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
#include <mpm/core/step/affine_transfer.h>
#include <mpm/core/step/backend_traits.h>
#include <mpm/core/step/exchange.h>
#include <mpm/core/step/particles_to_grid.h>
#include <mpm/core/step/point_domain.h>
#include <mpm/core/step/pressure_averaging.h>
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
    // G2P velocity of point i: FLIP v_p + dt sum N a_i blended with PIC sum N v_i^{n+1},
    //   alpha (v_p + dt sum N a_i) + (1 - alpha) sum N v_i = alpha v_p + sum N w_i,
    // with w_i = alpha dt a_i + (1 - alpha) v_i left in force[] by update_grid.
    // stencil(visit) visits the point's stencil nodes (for_each_stencil_node).
    template <int dim, typename Real, typename Stencil>
    MPM_HOST_DEVICE inline void updated_point_velocity(const GridView<dim, Real> &g, const PointsView<dim, Real> &p,
                                                       const StepSettings<dim, Real> &s, const int i,
                                                       Stencil &&stencil, Real v_new[dim])
    {
      Real nodal[dim] = {};
      stencil([&](const int n, const Real N, const Real *) {
        for (int d = 0; d < dim; ++d)
          nodal[d] += N * g.force[d][n];
      });
      for (int d = 0; d < dim; ++d)
        v_new[d] = s.flip_fraction * p.velocity[d][i] + nodal[d];
    }

    // G2P velocity (USL, USF).
    template <int dim, typename Shape, DevicePhysics physics = DevicePhysics::standard, typename Real,
              typename Backend>
    void grid_to_particle_velocity(Backend &backend, const GridView<dim, Real> &g,
                                   const PointsView<dim, Real> &p, const StepSettings<dim, Real> &s)
    {
      backend.template gather_points<Real>(p.n_points, [=] MPM_HOST_DEVICE(const int i) {
        if (p.material[i] < 0)
          return;
        Real x[dim], lp[domain_values<dim, Shape>()], v_new[dim];
        for (int d = 0; d < dim; ++d)
          x[d] = p.position[d][i];
        load_domain<dim, Shape>(p, s, i, lp);
        updated_point_velocity<dim>(
          g, p, s, i, [&](auto &&visit) { for_each_stencil_node<dim, Shape>(g, x, lp, visit); }, v_new);
        for (int d = 0; d < dim; ++d)
          p.velocity[d][i] = v_new[d];
        if constexpr (all_physics_compiled<physics>())
          if (s.affine_state_variable >= 0) // from v^{n+1}, which update_grid left in force[] (flip_fraction 0)
            {
              Real C[dim * dim];
#if defined(__CUDA_ARCH__) || defined(MPM_UNROLL_STENCIL)
              affine_matrix_of<dim, Shape>(g, g.force, PointStencil<dim, Shape, Real>{x, lp}, x, s.affine_matrix, C);
#else
              affine_matrix_of<dim, Shape>(g, g.force, HostStencil<dim, Shape, Real>(g, x, lp), x, s.affine_matrix,
                                           C);
#endif
              store_affine(p, s, i, C);
            }
      });
    }

    // MUSL: G2P velocity, then the remap of the nodal momentum from the updated point
    // velocities, sum N m_p v_p, rebuilt from zero (update_grid left it zero). Fused into
    // one pass over the points, which reads each point once for both (the remap reads only
    // what the gather wrote and the grid's velocity and acceleration, which it does not
    // write).
    template <int dim, typename Shape, DevicePhysics physics = DevicePhysics::standard, typename Real,
              typename Backend>
    void grid_to_particle_velocity_and_remap(Backend &backend, const GridView<dim, Real> &g,
                                             const PointsView<dim, Real> &p, const StepSettings<dim, Real> &s,
                                             const void *stencils = nullptr)
    {
      backend.scatter_points(p.n_points, [=] MPM_HOST_DEVICE(const int i) {
        if (p.material[i] < 0)
          return;
        Real x[dim], lp[domain_values<dim, Shape>()], v_new[dim], mv[dim];
        for (int d = 0; d < dim; ++d)
          x[d] = p.position[d][i];
        load_domain<dim, Shape>(p, s, i, lp);
        (void)stencils; // captured in both compilation passes (nvcc's extended lambdas need the same captures)
#if defined(__CUDA_ARCH__) || defined(MPM_UNROLL_STENCIL)
        auto stencil = [&](auto &&visit) { for_each_stencil_node<dim, Shape>(g, x, lp, visit); };
#else
        // Host: the stencil's weights evaluated once for the gather and the scatter (the
        // same values as two for_each_stencil_node calls), or those P2G kept.
        HostStencil<dim, Shape, Real>        own;
        const HostStencil<dim, Shape, Real> *host_stencil =
          stencils != nullptr ? static_cast<const HostStencil<dim, Shape, Real> *>(stencils) + i :
                                (own = HostStencil<dim, Shape, Real>(g, x, lp), &own);
        auto stencil = [&](auto &&visit) { host_stencil->for_each(g, visit); };
#endif
        updated_point_velocity<dim>(g, p, s, i, stencil, v_new);
        const Real m = p.mass[i];
        for (int d = 0; d < dim; ++d)
          {
            p.velocity[d][i] = v_new[d];
            mv[d]            = m * v_new[d];
          }
        Real                                 *targets[dim];
        StencilContribution<dim, dim, 0, Real> momentum;
        for (int d = 0; d < dim; ++d)
          {
            targets[d]        = g.momentum[d];
            momentum.c_N[d] = mv[d];
          }
#if defined(__CUDA_ARCH__) || defined(MPM_UNROLL_STENCIL)
        Backend::template scatter_stencil<dim, Shape, true>(g, x, lp, targets, momentum); // the kernel's only one
        const PointStencil<dim, Shape, Real> affine_stencil{x, lp};
#else
        add_contribution<Backend>(stencil, targets, momentum);
        const HostStencil<dim, Shape, Real> &affine_stencil = *host_stencil;
#endif
        if constexpr (all_physics_compiled<physics>())
          if (s.affine_state_variable >= 0) // C from v^{n+1} (force[], flip_fraction 0), then its momentum
            {
              Real C[dim * dim];
              affine_matrix_of<dim, Shape>(g, g.force, affine_stencil, x, s.affine_matrix, C);
              store_affine(p, s, i, C);
              if constexpr (!atomic_scatter<Backend>::value) // atomic backends: add_affine_momentum
                add_apic_momentum<Backend, dim>(g, affine_stencil, x, m, C);
            }
      });
    }

    // The entries of point i that its kinematics reads only after storing its new position
    // (the compiler may not move those loads above the store): asked into L2 before the
    // stencil's gather, so that they arrive while it runs instead of one DRAM round trip
    // after another. The device only (prefetch.h); no effect on any result.
    template <int dim, typename Real>
    MPM_HOST_DEVICE inline void prefetch_constitutive_state(const PointsView<dim, Real> &p,
                                                            const StepSettings<dim, Real> &s, const int i)
    {
      for (int k = 0; k < dim * dim; ++k)
        prefetch_to_l2(p.deformation_gradient[k] + i);
      prefetch_to_l2(p.volume + i);
      prefetch_to_l2(p.initial_volume + i);
      for (int c = 0; c < n_voigt; ++c)
        {
          prefetch_to_l2(p.stress[c] + i);
          prefetch_to_l2(p.strain[c] + i);
        }
      prefetch_to_l2(p.plastic_strain + i);
      if (s.domain_update != DomainUpdate::none)
        for (int d = 0; d < dim; ++d)
          prefetch_to_l2(p.initial_domain_half_length[d] + i);
    }

    // G2P kinematics from the nodal velocity field, then per point: position,
    // strain and spin increments, volume and particle domain, constitutive update.
    // A point whose centre leaves the grid is marked removed (material = -1).
    // The particle domain is rescaled only in the pass that moves the points, so that
    // every transfer of one step uses the same stencil (USF deforms before it moves).
    // carry_p2g (atomic backends only, explicit_step's FusedTransfer): each point's P2G of
    // the next step too, with next_gravity_given, after its own update (the grid's mass,
    // momentum and force zeroed before). A template argument, so that the unfused pass holds
    // no P2G (and the fused one the stencil scatter's shared records instead of add_to_node's
    // staging area).
    template <int dim, typename Shape, DevicePhysics physics = DevicePhysics::standard, bool carry_p2g = false,
              typename Real, typename Backend>
    void grid_to_particle_kinematics(Backend &backend, const GridView<dim, Real> &g,
                                     const PointsView<dim, Real> &p,
                                     const MaterialParameters<Real> *materials,
                                     const StepSettings<dim, Real> &s, const Real dt_given,
                                     const bool move_points, const bool deform_points,
                                     const void *stencils = nullptr, const bool scatter_pressure = false,
                                     const Real *next_gravity_given = nullptr)
    {
      // scatter_pressure (atomic backends only): the first pass of the pressure averaging
      // too, at the end of each point's update (one pass over the points less).
      if constexpr (!atomic_scatter<Backend>::value)
        if (scatter_pressure || carry_p2g)
          throw std::invalid_argument("grid_to_particle_kinematics: this backend scatters only in scatter_points");
      if (carry_p2g && (scatter_pressure || next_gravity_given == nullptr))
        throw std::invalid_argument("grid_to_particle_kinematics: the next step's P2G needs its gravity and no "
                                    "pressure averaging");
      Gravity<dim, Real> next_gravity; // captured by value (the kernel's argument)
      for (int d = 0; d < dim; ++d)
        next_gravity.g[d] = next_gravity_given != nullptr ? next_gravity_given[d] : Real(0);
      const MaterialParameters<Real> *disconnecting = disconnecting_materials(s, materials);
      backend.template gather_points<Real>(p.n_points, [=] MPM_HOST_DEVICE(const int i) {
        if (p.material[i] < 0)
          return;
        const Real dt = time_step_of(s, dt_given);
        Real x[dim], lp[domain_values<dim, Shape>()], dx[dim] = {};
        Mat3<Real> L = Mat3<Real>::zero(); // velocity gradient; plane strain keeps row/column z zero
        for (int d = 0; d < dim; ++d)
          x[d] = p.position[d][i];
        load_domain<dim, Shape>(p, s, i, lp);
#if !defined(MPM_NO_PREFETCH)
        if (deform_points)
          prefetch_constitutive_state(p, s, i);
#endif
        auto visit = [&](const int n, const Real N, const Real *grad) {
          for (int d = 0; d < dim; ++d)
            {
              const Real v = g.velocity[d][n];
              dx[d] += N * v;
              for (int e = 0; e < dim; ++e)
                L.a[d][e] += v * grad[e];
            }
        };
        (void)stencils; // captured in both compilation passes (nvcc's extended lambdas need the same captures)
#if defined(__CUDA_ARCH__) || defined(MPM_UNROLL_STENCIL)
        for_each_stencil_node<dim, Shape>(g, x, lp, visit);
#else
        if (stencils != nullptr) // kept by P2G: the points have not moved since
          static_cast<const HostStencil<dim, Shape, Real> *>(stencils)[i].for_each(g, visit);
        else
          HostStencil<dim, Shape, Real>(g, x, lp).for_each(g, visit);
#endif

        // The position first: x and dx are then dead before the constitutive update, the
        // largest live state of the kernel (the CUDA gathers run under a register cap).
        bool       leaves_grid = false;
        const bool move        = move_points && !s.hold_points;
        // GIMP's domain from the point's F and J (domain_update.h), after both are updated.
        auto rescale_domain = [&](const Real *f, const Real J) {
          Real scale[dim], initial[dim]; // every load before the first store, as below
          for (int d = 0; d < dim; ++d)
            initial[d] = p.initial_domain_half_length[d][i];
          gimp_domain_scale<dim, all_physics_compiled<physics>()>(s.domain_update, f, J, scale);
          for (int d = 0; d < dim; ++d)
            {
              // GIMP weights are valid up to half a cell.
              const Real l = initial[d] * scale[d];
              p.domain_half_length[d][i] = l < Real(0.5) * g.h ? l : Real(0.5) * g.h;
            }
        };
        if (move)
          for (int d = 0; d < dim; ++d)
            {
              const Real xn      = x[d] + dt * dx[d];
              p.position[d][i]   = xn;
              const Real s_local = (xn - g.origin[d]) / g.h;
              // Also catches NaN, which compares false.
              if (!(s_local >= Real(0) && s_local <= Real(g.n_cells[d])))
                leaves_grid = true;
            }
        if (leaves_grid && s.wall_faces != 0) // a wall stops the centre on its face
          {
            Real xn[dim];
            for (int d = 0; d < dim; ++d)
              xn[d] = p.position[d][i];
            leaves_grid = !stop_at_walls<dim>(s.wall_faces, g.origin, g.h, g.n_cells, xn);
            for (int d = 0; d < dim; ++d)
              p.position[d][i] = xn[d];
          }

        if (deform_points)
          {
            Mat3<Real> dF = Mat3<Real>::identity(), dW;
            for (int a = 0; a < 3; ++a)
              for (int b = 0; b < 3; ++b)
                {
                  dF.a[a][b] += dt * L.a[a][b];
                  dW.a[a][b] = Real(0.5) * dt * (L.a[a][b] - L.a[b][a]);
                }
            Mat3<Real> Ldt;
            for (int a = 0; a < 3; ++a)
              for (int b = 0; b < 3; ++b)
                Ldt.a[a][b] = dt * L.a[a][b];
            const SymTensor<Real> d_eps = symmetric_part(Ldt);

            StepKinematics<Real> kinematics;
            kinematics.d_eps  = d_eps;
            kinematics.d_spin = dW;
            kinematics.f      = dF;
            const Real initial_volume = p.initial_volume[i];
            Real       volume         = p.volume[i];
            kinematics.J              = volume / initial_volume; // before the update below
            // F <- (I + L dt) F; the volume by det(I + L dt), whose product over the steps is
            // det F: computed from F it would lose its digits where F is far from a rotation
            // (a point sheared along a no-slip base: entries of thousands, det F of a few, and
            // in float none of its digits left, a negative volume; doc/methods.md).
            if (!s.hold_points)
              {
                Mat3<Real> F = Mat3<Real>::identity();
                for (int a = 0; a < dim; ++a)
                  for (int b = 0; b < dim; ++b)
                    F.a[a][b] = p.deformation_gradient[a * dim + b][i];
                F = multiply(dF, F);
                for (int a = 0; a < dim; ++a)
                  for (int b = 0; b < dim; ++b)
                    p.deformation_gradient[a * dim + b][i] = F.a[a][b];
                volume *= determinant(dF);
                p.volume[i] = volume;
                // The domain here, from F and the volume still in registers (reading them back
                // would wait on the stores above); move implies !hold_points.
                if (s.domain_update != DomainUpdate::none && move)
                  {
                    Real f[dim * dim];
                    for (int a = 0; a < dim; ++a)
                      for (int b = 0; b < dim; ++b)
                        f[a * dim + b] = F.a[a][b];
                    rescale_domain(f, volume / initial_volume);
                  }
              }
            kinematics.J_new = volume / initial_volume;
            MaterialPointState<Real> state;
            for (int c = 0; c < n_voigt; ++c)
              state.stress[c] = p.stress[c][i];
            state.plastic_strain = p.plastic_strain[i];
#ifndef __CUDA_ARCH__
            // A user model's state variables (CPU only: the GPU runs built-in models).
            Real variables[max_state_variables];
            for (int k = 0; k < p.n_state_variables; ++k)
              variables[k] = p.state_variables[k][i];
            if (p.n_state_variables > 0)
              state.state_variables = variables;
#endif
            const MaterialParameters<Real> &material = materials[p.material[i]];
            if (material.field_parameter == FieldParameter::none)
              update_stress<all_physics_compiled<physics>()>(material, kinematics, state);
            else
              update_stress<all_physics_compiled<physics>()>(with_field_value(material, p.material_field[i]),
                                                             kinematics, state);
            // Every strain read before any store: a store may alias a later load, which would
            // then wait for it (on the device one memory round trip per component).
            Real strain[n_voigt];
            for (int c = 0; c < n_voigt; ++c)
              strain[c] = p.strain[c][i] + d_eps[c];
            for (int c = 0; c < n_voigt; ++c)
              {
                p.stress[c][i] = state.stress[c];
                p.strain[c][i] = strain[c];
              }
            p.plastic_strain[i] = state.plastic_strain;
#ifndef __CUDA_ARCH__
            for (int k = 0; k < p.n_state_variables; ++k)
              p.state_variables[k][i] = variables[k];
#endif
          }

        if (s.domain_update != DomainUpdate::none && move && !deform_points)
          {
            Real f[dim * dim];
            for (int k = 0; k < dim * dim; ++k)
              f[k] = p.deformation_gradient[k][i];
            rescale_domain(f, p.volume[i] / p.initial_volume[i]);
          }

        if constexpr (Shape::tracks_corners)
          if (move)
            {
              // CPDI2q: each corner moves with the grid's velocity at it, kept as its offset from
              // the point's rectangle: the point moved by dt dx above, the corner by dt v_c.
              for (int c = 0; c < (1 << dim); ++c)
                {
                  Real xc[dim], vc[dim] = {};
                  for (int d = 0; d < dim; ++d)
                    xc[d] = x[d] + lp[c * dim + d];
                  visit_corner_cell<dim>(g, xc, [&](const int n, const Real N, const int *) {
                    for (int d = 0; d < dim; ++d)
                      vc[d] += N * g.velocity[d][n];
                  });
                  for (int d = 0; d < dim; ++d)
                    p.state_variables[s.corner_state_variable + c * dim + d][i] += dt * (vc[d] - dx[d]);
                }
            }

        if (leaves_grid)
          p.material[i] = -1;
        else if (scatter_pressure)
          add_cell_pressure_atomically<Backend, !carry_p2g>(g, p, i, disconnecting);
        else
          next_point_to_grid<carry_p2g, Backend, dim, Shape>(g, p, s, i, next_gravity);
      });
    }
  } // namespace stages
} // namespace mpm
