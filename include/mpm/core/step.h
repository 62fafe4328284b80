// One explicit MPM step with lumped mass, written once for every backend.
//
// A Backend says how loops run (see backend/cpu_backend.h): for_each_node,
// gather_points (a point writes only its own data), scatter_points (points add into
// the nodes of their stencil through Backend::scatter_stencil, or into a cell through
// Backend::add_to_node), reduce_points. The
// stages below are what MUSL, USL and USF are made of; explicit_step() reads as the
// algorithm (doc/theory.md).
#pragma once

#include <mpm/core/cubic_bspline_gimp.h>
#include <mpm/core/domain_update.h>
#include <mpm/core/interpolation.h>
#include <mpm/core/local_damping.h>
#include <mpm/core/material/material.h>
#include <mpm/core/prefetch.h>
#include <mpm/core/shape/shape_family.h>
#include <mpm/core/small_tensor.h>
#include <mpm/core/stencil_contribution.h>
#include <mpm/core/step/affine_transfer.h>
#include <mpm/core/step/backend_traits.h>
#include <mpm/core/step/exchange.h>
#include <mpm/core/step/grid_to_particles.h>
#include <mpm/core/step/grid_update.h>
#include <mpm/core/step/particles_to_grid.h>
#include <mpm/core/step/point_domain.h>
#include <mpm/core/step/pressure_averaging.h>
#include <mpm/core/step/reduction.h>
#include <mpm/core/step/settings.h>
#include <mpm/core/views.h>
#include <mpm/core/wall_friction.h>

namespace mpm
{

  // One step of the chosen scheme. Returns the reductions needed for the next time
  // step and for the time history.
  // physics: which physics the device's kernels hold (DevicePhysics); the host's hold all. On the
  // device a material with Hencky's law or Mohr-Coulomb needs DevicePhysics::all: the standard
  // kernels run the Jaumann rate form for the one and give the other a NaN stress, and the
  // material table lives on the device, so this cannot check it (DeviceEngine picks the variant
  // from the host's table, materials_need_all_physics).
  template <int dim, typename Shape, DevicePhysics physics = DevicePhysics::standard, typename Real, typename Backend,
            typename Exchange = NoGridExchange>
  StepReduction<Real> explicit_step(Backend &backend, const GridView<dim, Real> &g,
                                    const PointsView<dim, Real> &p,
                                    const MaterialParameters<Real> *materials,
                                    const StepSettings<dim, Real> &s, const Real dt,
                                    const Exchange &exchange = Exchange(), bool *averaging_pending = nullptr,
                                    FusedTransfer<dim, Real> *fused = nullptr)
  {
    using namespace stages;
    // The fused step (FusedTransfer): this step's P2G ran in the last one (carried), and/or
    // this one runs the next one's (carry).
    const bool carried = fused != nullptr && fused->p2g_carried;
    const bool carry   = fused != nullptr && fused->carry_next;
    if (carried || carry)
      {
        if (!atomic_scatter<Backend>::value)
          throw std::invalid_argument("explicit_step: the fused step needs a backend whose scatter is atomic");
        if (s.scheme == UpdateScheme::usf)
          throw std::invalid_argument("explicit_step: the fused step runs MUSL and USL (USF's last pass does not "
                                      "deform the points)");
        if (s.pressure_averaging || s.hold_points || s.affine_state_variable >= 0)
          throw std::invalid_argument("explicit_step: the fused step runs without pressure averaging (the next "
                                      "P2G reads the averaged stresses), held points and affine transfers");
      }
    if (atomic_scatter<Backend>::value && physics != DevicePhysics::all && s.domain_update == DomainUpdate::U)
      throw std::invalid_argument("explicit_step: GIMP's domains by U need the device's kernels compiled with them "
                                  "(explicit_step<dim, Shape, DevicePhysics::all>)");
    if (s.affine_state_variable >= 0)
      {
        if (atomic_scatter<Backend>::value && physics != DevicePhysics::all)
          throw std::invalid_argument("explicit_step: the affine transfers need the device's kernels compiled with "
                                      "them (explicit_step<dim, Shape, DevicePhysics::all>)");
        if (s.flip_fraction != Real(0))
          throw std::invalid_argument("explicit_step: APIC needs flip_fraction = 0 (its velocity is PIC's)");
        if (p.n_state_variables < s.affine_state_variable + dim * dim)
          throw std::invalid_argument("explicit_step: APIC's affine matrix needs dim x dim state variables");
        if (s.affine_matrix == AffineMatrix::b_d_inverse && !Shape::apic)
          throw std::invalid_argument("explicit_step: APIC (B D^-1) needs a shape function with a constant D_p "
                                      "(the B-splines) or linear weights; GIMP has neither (TPIC runs with it)");
      }
    if constexpr (Shape::tracks_corners)
      if (s.corner_state_variable < 0 || p.n_state_variables < s.corner_state_variable + (1 << dim) * dim)
        throw std::invalid_argument("explicit_step: CPDI2q's corners need 2^dim x dim state variables "
                                    "(StepSettings::corner_state_variable)");
    if (s.body_force_state_variable >= 0)
      {
        if (atomic_scatter<Backend>::value)
          throw std::invalid_argument("explicit_step: a point's own body force runs on host backends only");
        if (p.n_state_variables < s.body_force_state_variable + dim)
          throw std::invalid_argument("explicit_step: a point's own body force needs dim state variables");
      }
    // The arrays summed over ranks after each P2G (MPI): after the first, mass, momentum
    // and force in one exchange (one round of messages, and on the GPU one staging).
    Real *mass_and_momentum[dim + 1], *momentum[dim], *forces[dim], *p2g_sums[2 * dim + 1];
    mass_and_momentum[0] = p2g_sums[0] = g.mass;
    for (int d = 0; d < dim; ++d)
      {
        mass_and_momentum[d + 1] = momentum[d] = p2g_sums[d + 1] = g.momentum[d];
        forces[d] = p2g_sums[dim + 1 + d] = g.force[d];
      }

    // The last step's averaging, deferred to this step's P2G (MUSL, USL).
    const bool apply_pending = averaging_pending != nullptr && *averaging_pending && s.pressure_averaging &&
                               s.scheme != UpdateScheme::usf;
    if (averaging_pending != nullptr && *averaging_pending && !apply_pending)
      throw std::invalid_argument("explicit_step: a deferred pressure averaging is pending but this step does not "
                                  "apply it (finish_pressure_averaging first)");
    // MUSL and USL: the averaging's first pass after the kinematics, or in it where the
    // backend's scatter is atomic (one pass over the points less); its second pass below
    // or, deferred, in the next P2G.
    const bool scatter_in_kinematics = s.pressure_averaging && atomic_scatter<Backend>::value;
    const MaterialParameters<Real> *disconnecting = disconnecting_materials(s, materials);
    auto       scatter_averaged_pressure = [&]() {
      if (!s.pressure_averaging)
        return;
      if (scatter_in_kinematics)
        {
          Real *cell_sums[2] = {g.cell_volume, g.cell_pressure_volume};
          sum_cells(exchange, cell_sums, 2, 0);
          return;
        }
      group_for_scatter<dim, Shape>(backend, g, p, s); // the points have moved
      scatter_cell_pressure(backend, g, p, exchange, disconnecting);
    };
    // Atomic backends add the affine transfers' momentum in a pass of its own, after each P2G of
    // the momentum (add_affine_momentum).
    auto affine_momentum = [&](const PointsView<dim, Real> &q) {
      if constexpr (atomic_scatter<Backend>::value && physics == DevicePhysics::all)
        if (s.affine_state_variable >= 0)
          add_affine_momentum<dim, Shape>(backend, g, q, s);
    };
    group_for_scatter<dim, Shape>(backend, g, p, s);
    // MUSL and USL: the passes before an exchange (P2G, the remap, the kinematics with the
    // averaging's cell sums) overlap it where the exchange can (pass_then_sum). Only where
    // the scatter is atomic: host backends keep each point's stencil, and its colour, by the
    // point's index, so their passes are never split.
    int n_first = -1;
    if constexpr (overlaps_exchange<Exchange>::value && atomic_scatter<Backend>::value)
      n_first = exchange.points_before_overlap();
    auto sum_nodal = [&](Real *const *arrays, const int count) {
      return [&exchange, arrays, count]() { exchange.sum_nodal(arrays, count); };
    };
    // P2G of mass, momentum and force (applying a deferred averaging), then their sums.
    auto particles_to_grid_then_sum = [&](void *stencils) {
      pass_then_sum(
        exchange, n_first, p,
        [&](const PointsView<dim, Real> &q) {
          particles_to_grid<dim, Shape, physics>(backend, g, q, s, true, true, stencils, apply_pending, disconnecting);
          affine_momentum(q);
        },
        ExchangedEntries::nodes, p2g_sums, 2 * dim + 1, sum_nodal(p2g_sums, 2 * dim + 1));
    };
    Real *cell_sums[2] = {g.cell_volume, g.cell_pressure_volume};
    // The kinematics pass, then the averaging's cell sums where it scattered them.
    auto kinematics_then_cell_sums = [&](auto &&kinematics) {
      if (scatter_in_kinematics)
        pass_then_sum(exchange, n_first, p, kinematics, ExchangedEntries::cells, cell_sums, 2,
                      [&]() { sum_cells(exchange, cell_sums, 2, 0); });
      else
        {
          kinematics(p);
          scatter_averaged_pressure();
        }
    };
    // MUSL and USL: the grid zeroed and P2G, or only the sums where the last step ran this P2G.
    auto p2g_unless_carried = [&](void *stencils) {
      if (carried)
        {
          exchange.sum_nodal(p2g_sums, 2 * dim + 1);
          return;
        }
      reset_grid(backend, g, true, s.pressure_averaging && !apply_pending);
      particles_to_grid_then_sum(stencils);
    };
    // The kinematics carrying the next step's P2G into a grid zeroed after the nodal
    // velocities, the only nodal values the kinematics reads, are formed.
    auto carry_next_p2g = [&]() {
      if constexpr (atomic_scatter<Backend>::value) // the others are refused above
        {
          reset_grid(backend, g, true);
          grid_to_particle_kinematics<dim, Shape, physics, true>(backend, g, p, materials, s, dt, true, true,
                                                                 nullptr, false, fused->next_gravity);
        }
    };
    switch (s.scheme)
      {
        case UpdateScheme::musl:
          {
            // Host backends with point scratch: P2G keeps each point's stencil for the
            // remap and the kinematics (the points move only at the end of the latter).
            void *stencils = nullptr;
#if !defined(__CUDA_ARCH__) && !defined(MPM_UNROLL_STENCIL)
            if constexpr (has_point_scratch<Backend>::value)
              stencils = backend.point_scratch(p.n_points, sizeof(HostStencil<dim, Shape, Real>));
#endif
            p2g_unless_carried(stencils);
            update_grid(backend, g, s, dt, true, apply_pending);
            pass_then_sum(
              exchange, n_first, p,
              [&](const PointsView<dim, Real> &q) {
                grid_to_particle_velocity_and_remap<dim, Shape, physics>(backend, g, q, s, stencils);
                affine_momentum(q);
              },
              ExchangedEntries::nodes, momentum, dim, sum_nodal(momentum, dim));
            if (!s.hold_points || s.hold_from_point_momentum) // held, the grid keeps its updated ones
              velocity_from_momentum(backend, g, s.mass_tolerance);
            if (carry)
              carry_next_p2g();
            else
              kinematics_then_cell_sums([&](const PointsView<dim, Real> &q) {
                grid_to_particle_kinematics<dim, Shape, physics>(backend, g, q, materials, s, dt, true, true,
                                                                 stencils, scatter_in_kinematics);
              });
          }
          break;

        case UpdateScheme::usl:
          p2g_unless_carried(nullptr);
          update_grid(backend, g, s, dt, false, apply_pending);
          grid_to_particle_velocity<dim, Shape, physics>(backend, g, p, s);
          if (carry)
            carry_next_p2g();
          else
            kinematics_then_cell_sums([&](const PointsView<dim, Real> &q) {
              grid_to_particle_kinematics<dim, Shape, physics>(backend, g, q, materials, s, dt, true, true, nullptr,
                                                               scatter_in_kinematics);
            });
          break;

        case UpdateScheme::usf:
          reset_grid(backend, g, true);
          particles_to_grid<dim, Shape, physics>(backend, g, p, s, true, false);
          affine_momentum(p);
          exchange.sum_nodal(mass_and_momentum, dim + 1);
          if (!s.hold_points || s.hold_from_point_momentum) // held, the last step's grid velocities
            velocity_from_momentum(backend, g, s.mass_tolerance);
          grid_to_particle_kinematics<dim, Shape, physics>(backend, g, p, materials, s, dt, false, true);
          if (s.pressure_averaging)
            average_cell_pressure(backend, g, p, exchange, disconnecting);
          particles_to_grid<dim, Shape, physics>(backend, g, p, s, false, true);
          exchange.sum_nodal(forces, dim);
          update_grid(backend, g, s, dt);
          grid_to_particle_velocity<dim, Shape, physics>(backend, g, p, s);
          grid_to_particle_kinematics<dim, Shape, physics>(backend, g, p, materials, s, dt, true, false);
          break;
      }
    if constexpr (colours_scatter<Backend>::value)
      backend.ungroup(); // the points have moved: the next group_for_scatter checks the grouping again
    if (fused != nullptr)
      fused->p2g_carried = carry;
    // MUSL and USL average at the end of the step. Deferred (averaging_pending given), the
    // points keep their stresses before the averaging and the grid its cell sums: the next
    // step's P2G applies it as it reads the stresses (one pass over the points less), and
    // finish_pressure_averaging() does where the points are read before that.
    const bool averaged_last = s.pressure_averaging && s.scheme != UpdateScheme::usf;
    if (averaging_pending != nullptr)
      {
        *averaging_pending = averaged_last;
        return reduce_step(backend, g, p, s, false);
      }
    return reduce_step(backend, g, p, s, averaged_last, disconnecting);
  }

  // Dispatch on the shape function chosen at run time.
  template <int dim, DevicePhysics physics = DevicePhysics::standard, typename Real, typename Backend,
            typename Exchange = NoGridExchange>
  StepReduction<Real> explicit_step(Backend &backend, const ShapeFunction shape,
                                    const GridView<dim, Real> &g, const PointsView<dim, Real> &p,
                                    const MaterialParameters<Real> *materials,
                                    const StepSettings<dim, Real> &s, const Real dt,
                                    const Exchange &exchange = Exchange(), bool *averaging_pending = nullptr,
                                    FusedTransfer<dim, Real> *fused = nullptr)
  {
    StepReduction<Real> reduction{};
    with_shape(shape, [&](auto member) {
      using Shape = decltype(member);
      if constexpr (dim == 3 && !Shape::in_3d)
        throw std::invalid_argument(std::string("explicit_step: ") + Shape::name + " is two-dimensional");
      else if constexpr (atomic_scatter<Backend>::value && physics != DevicePhysics::all &&
                         Shape::owner != ShapeOwner::always)
        throw std::invalid_argument(std::string("explicit_step: the shape function ") + Shape::name +
                                    " is compiled into the device's DevicePhysics::all kernels only "
                                    "(shape_needs_all_physics)");
      else
        reduction = explicit_step<dim, Shape, physics>(backend, g, p, materials, s, dt, exchange, averaging_pending,
                                                       fused);
    });
    return reduction;
  }
} // namespace mpm
