// P2G: nodal mass, momentum, internal and gravity forces from the points.
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
    // P2G of point i (not removed): nodal mass and momentum, and/or internal
    // (-V sigma . grad N) and gravity forces. particles_to_grid runs it for every point; the
    // fused step (explicit_step, FusedTransfer) at the end of each point's kinematics.
    template <typename Backend, int dim, typename Shape, typename Real>
    MPM_HOST_DEVICE MPM_ALWAYS_INLINE void point_to_grid(const GridView<dim, Real> &g, const PointsView<dim, Real> &p,
                                                         const StepSettings<dim, Real> &s, const int i,
                                                         const bool mass_and_momentum, const bool forces,
                                                         void *stencils, const bool apply_averaging,
                                                         const MaterialParameters<Real> *disconnecting,
                                                         const Real *gravity)
    {
      Real x[dim], lp[domain_values<dim, Shape>()], v[dim];
      for (int d = 0; d < dim; ++d)
        {
          x[d]  = p.position[d][i];
          v[d]  = p.velocity[d][i];
        }
      load_domain<dim, Shape>(p, s, i, lp);
      const Real m = p.mass[i], V = p.volume[i];
      SymTensor<Real> sigma;
      for (int c = 0; c < n_voigt; ++c)
        sigma[c] = p.stress[c][i];
      if (apply_averaging && averages_pressure(disconnecting, p, i)) // the last step's, left pending (explicit_step)
        {
          const Real shift = cell_pressure_shift(g, x, sigma[0], sigma[1], sigma[2]);
          for (int k = 0; k < 3; ++k)
            {
              sigma[k] += shift;
              p.stress[k][i] = sigma[k];
            }
        }

      // Nodal arrays in the order of the values: mass, momentum, force. Each value is
      // linear in N and grad N (stencil_contribution.h): mass m N, momentum m v N, force
      // m g N - V sigma . grad N.
      constexpr int K = 2 * dim + 1;
      Real         *targets[K];
      targets[0] = g.mass;
      for (int d = 0; d < dim; ++d)
        {
          targets[1 + d]       = g.momentum[d];
          targets[1 + dim + d] = g.force[d];
        }
      StencilContribution<dim, K, dim, Real> all;
      all.c_N[0] = m;
      for (int d = 0; d < dim; ++d)
        {
          all.c_N[1 + d]       = m * v[d];
          all.c_N[1 + dim + d] = m * gravity[d];
#ifndef __CUDA_ARCH__
          if (s.body_force_state_variable >= 0)
            all.c_N[1 + dim + d] += m * p.state_variables[s.body_force_state_variable + d][i];
#endif
          for (int e = 0; e < dim; ++e)
            all.c_grad[d][e] = -V * sigma(d, e);
        }
      (void)stencils; // the host keeps them; the device computes each stencil again
#if defined(__CUDA_ARCH__) || defined(MPM_UNROLL_STENCIL)
      auto scatter = [&](const auto &contribution, Real *const *into) {
        Backend::template scatter_stencil<dim, Shape>(g, x, lp, into, contribution);
      };
#else
      // Host: the stencil, kept for the later stages of the step where they asked for it.
      const HostStencil<dim, Shape, Real> stencil(g, x, lp);
      if (stencils != nullptr)
        static_cast<HostStencil<dim, Shape, Real> *>(stencils)[i] = stencil;
      auto scatter = [&](const auto &contribution, Real *const *into) {
        add_contribution<Backend>([&](auto &&visit) { stencil.for_each(g, visit); }, into, contribution);
      };
#endif
      if (mass_and_momentum && forces)
        scatter(all, targets);
      else if (mass_and_momentum)
        {
          StencilContribution<dim, dim + 1, 0, Real> mass_momentum;
          for (int k = 0; k <= dim; ++k)
            mass_momentum.c_N[k] = all.c_N[k];
          scatter(mass_momentum, targets);
        }
      else if (forces)
        {
          StencilContribution<dim, dim, dim, Real> force;
          for (int d = 0; d < dim; ++d)
            {
              force.c_N[d] = all.c_N[1 + dim + d];
              for (int e = 0; e < dim; ++e)
                force.c_grad[d][e] = all.c_grad[d][e];
            }
          scatter(force, targets + dim + 1);
        }
      // Atomic backends: add_affine_momentum, after this pass.
      if constexpr (!atomic_scatter<Backend>::value)
        if (mass_and_momentum && s.affine_state_variable >= 0)
          {
            Real C[dim * dim];
            load_affine(p, s, i, C);
#if defined(__CUDA_ARCH__) || defined(MPM_UNROLL_STENCIL)
            add_apic_momentum<Backend, dim>(g, PointStencil<dim, Shape, Real>{x, lp}, x, m, C);
#else
            add_apic_momentum<Backend, dim>(g, stencil, x, m, C);
#endif
          }
    }

    // P2G of every point.
    template <int dim, typename Shape, DevicePhysics physics = DevicePhysics::standard, typename Real,
              typename Backend>
    void particles_to_grid(Backend                          &backend,
                           const GridView<dim, Real>        &g,
                           const PointsView<dim, Real>      &p,
                           const StepSettings<dim, Real>    &s,
                           const bool                        mass_and_momentum,
                           const bool                        forces,
                           void                             *stencils = nullptr,
                           const bool                        apply_averaging = false,
                           const MaterialParameters<Real>   *disconnecting = nullptr)
    {
      backend.scatter_points(p.n_points, [=] MPM_HOST_DEVICE(const int i) {
        if (p.material[i] >= 0)
          point_to_grid<Backend, dim, Shape>(g, p, s, i, mass_and_momentum, forces, stencils, apply_averaging,
                                             disconnecting, s.gravity);
      });
    }

    // A gravity vector by value (a kernel's argument).
    template <int dim, typename Real>
    struct Gravity
    {
      Real g[dim];
    };

    // The fused step's P2G of the next step for point i at the end of its kinematics
    // (grid_to_particle_kinematics with carry_p2g); nothing without. Here and not in the
    // kinematics' lambda: nvcc's extended lambdas may not capture first inside if constexpr.
    template <bool carry_p2g, typename Backend, int dim, typename Shape, typename Real>
    MPM_HOST_DEVICE inline void next_point_to_grid(const GridView<dim, Real> &g, const PointsView<dim, Real> &p,
                                                   const StepSettings<dim, Real> &s, const int i,
                                                   const Gravity<dim, Real> &next_gravity)
    {
      if constexpr (carry_p2g)
        point_to_grid<Backend, dim, Shape>(g, p, s, i, true, true, nullptr, false,
                                           static_cast<const MaterialParameters<Real> *>(nullptr), next_gravity.g);
      else
        {
          (void)g, (void)p, (void)s, (void)i, (void)next_gravity;
        }
    }
  } // namespace stages
} // namespace mpm
