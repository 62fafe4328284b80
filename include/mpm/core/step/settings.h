// What one explicit step is asked to do (StepSettings), what it returns (StepReduction), the fused
// transfer's carry, and which physics the device's kernels compile (DevicePhysics).
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
  enum class UpdateScheme : int
  {
    musl = 0, // modified update stress last (default)
    usl  = 1, // update stress last
    usf  = 2  // update stress first
  };

  // The affine velocity matrix C_p of the affine transfers (StepSettings::affine_state_variable).
  enum class AffineMatrix : int
  {
    velocity_gradient = 0, // TPIC: C_p = sum_i v_i grad N_ip^T, any shape function
    b_d_inverse       = 1  // APIC (Jiang et al. 2015): C_p = B_p D_p^-1, B_p = sum_i N_ip v_i r_i^T, with
                           // the B-splines' constant D_p (h^2/4 quadratic, h^2/3 cubic); for linear
                           // weights it equals the gradient form; GIMP has no constant D_p (refused)
  };

  // What the device's kernels compile (explicit_step's template argument). The affine
  // transfers, Hencky's law, Mohr-Coulomb and U's domains cost every launch registers and time
  // where compiled in (Hencky alone: 4% of P1's step on the H100; Mohr-Coulomb and U with their
  // eigen decompositions most of the kinematics' spills, doc/log.md), so the device compiles
  // them only into a second variant of the step, run where a run asks for them
  // (settings_ and materials_need_all_physics, DeviceEngine). Host code compiles everything either way.
  enum class DevicePhysics : int
  {
    standard = 0, // the FLIP/PIC blend, the Jaumann rate form, linear elasticity and Drucker-Prager,
                  // GIMP's domains kept, scaled by det F or by F_ii
    all = 1       // also the affine transfers (TPIC, APIC), Hencky's law, Mohr-Coulomb, U's domains
  };

  // Whether the code being compiled holds DevicePhysics::all's physics (the affine transfers,
  // Hencky, Mohr-Coulomb, U's domains): always on the host, on the device where the step's
  // variant asks for them.
  template <DevicePhysics physics>
  MPM_HOST_DEVICE constexpr bool all_physics_compiled()
  {
#if defined(__CUDA_ARCH__)
    return physics == DevicePhysics::all;
#else
    return true;
#endif
  }

  template <int dim, typename Real>
  // Defaults are the prm's (an unset field was garbage: test_gpu_device_engine once stepped
  // with an arbitrary update scheme).
  struct StepSettings
  {
    UpdateScheme scheme = UpdateScheme::musl;
    Real         gravity[dim] = {}; // body acceleration at this step (ramp already applied)
    Real         damping      = Real(0); // local damping coefficient D
    LocalDampingForm damping_form = LocalDampingForm::per_component; // local_damping.h
    Real             damping_threshold = Real(0); // nodal speeds at or below it are not damped
    Real         flip_fraction  = Real(1);            // 1: pure FLIP, 0: pure PIC
    // FLIP at a node component that a boundary holds fixed. false (ep2-3De's): no velocity
    // change reaches the points, so a point beside a no-slip base keeps a velocity it does not
    // move with. true: the change the boundary made, from the node's velocity before the
    // update to zero, as at every other node.
    bool         flip_fixed_velocity_change = false;
    DomainUpdate domain_update  = DomainUpdate::none; // uGIMP or cpGIMP variants
    Real         mass_tolerance = Real(0);            // nodes lighter than this carry no velocity
    // Cell-wise volume-weighted pressure averaging after the constitutive update
    // (remedy for volumetric locking); needs the grid's cell arrays.
    bool pressure_averaging = false;
    // Some material disconnects points (MaterialParameters::disconnection_volume_ratio): the
    // averaging then leaves out the points that have (their volume, zero pressure and the
    // cell's mean). false: it never looks at the materials.
    bool disconnected_points = false;
    // The points hold their place and shape (position, F, volume, GIMP domain): only their
    // stresses follow the grid's velocities. The equilibration of an initial state uses it,
    // so that the MPM's equilibrium is found in the geometry handed over.
    bool hold_points = false;
    // With hold_points the grid keeps its velocities from step to step, as a dynamic
    // relaxation on the grid (FLAC's): a node's velocity before the update is the last held
    // step's, not one rebuilt from the points' momentum. Rebuilt, a light node at a free
    // surface (its mass from the tails of a few GIMP domains) sees almost none of its own
    // velocity come back through the points, so it never gathers speed: its stiff-less
    // modes relax over thousands of steps (doc/log.md). The first held step, with this
    // set, starts from the points' momentum.
    bool hold_from_point_momentum = false;
    // An affine transfer (APIC or TPIC, affine_matrix) instead of the FLIP/PIC blend: a point
    // carries an affine velocity matrix C_p (dim x dim, row-major) in
    // p.state_variables[affine_state_variable + a dim + b], its momentum reaches the grid as
    // m N_i (v_p + C_p (x_i - x_p)), and G2P gives PIC's velocity and C_p (affine_matrix_of).
    // flip_fraction must be 0. -1: neither. On the device the step's kernels must hold them
    // (explicit_step<..., DevicePhysics::all>; explicit_step refuses the standard ones).
    int          affine_state_variable = -1;
    AffineMatrix affine_matrix         = AffineMatrix::velocity_gradient;
    // A body acceleration of each point's own, added to gravity in P2G: dim state variables
    // from p.state_variables[body_force_state_variable] that the caller sets before each step
    // (the manufactured solutions of tests/core/manufactured_solution.h). -1: none. Host
    // backends (the state variables live on the host).
    int body_force_state_variable = -1;
    // CPDI2q (cpdi.h): each point's corners, as their offsets from the rectangle R_0 s_c
    // (2^dim x dim values, zero at the start) in p.state_variables[corner_state_variable + ...].
    int corner_state_variable = -1;
    // Bit f set: grid face f (x min, x max, y min, ...) is a rigid wall (no-slip, free-slip or
    // friction), where a point's centre stops instead of leaving the grid (stop_at_walls, wall_friction.h).
    // 0: every face is open, as the prm's default `free`.
    std::uint8_t wall_faces = 0;
    // Where a step is queued on the device before the last one's speeds are back on the host
    // (time_step_rule.h), its time step is read from here on the device instead of the dt
    // argument. nullptr: the argument. Not converted between precisions (converted<>()).
    const Real *time_step_on_device = nullptr;
  };

  // Whether a step with these settings, or these materials (any range of MaterialParameters),
  // needs the device's DevicePhysics::all kernels.
  template <int dim, typename Real>
  bool settings_need_all_physics(const StepSettings<dim, Real> &s)
  {
    return s.affine_state_variable >= 0 || s.domain_update == DomainUpdate::U;
  }

  template <typename Materials>
  bool materials_need_all_physics(const Materials &materials)
  {
    for (const auto &m : materials)
      if (m.elastic_law == ElasticLaw::hencky || !in_standard_kernels(m))
        return true;
    return false;
  }

  // The time step a step's kernels use: the argument, or the device's own (above).
  template <int dim, typename Real>
  MPM_HOST_DEVICE inline Real time_step_of(const StepSettings<dim, Real> &s, const Real dt)
  {
    return s.time_step_on_device != nullptr ? *s.time_step_on_device : dt;
  }

  // Per-step reductions over the points: the next time step needs the largest speed,
  // the time history the power of gravity.
  template <typename Real>
  struct StepReduction
  {
    Real max_speed;
    Real gravity_power;
    Real max_removed_speed; // speed of points that left the grid, frozen when they left:
                            // a blow-up that throws points out must not pass unnoticed
  };

  // The fused step (explicit_step's last argument; MUSL and USL on backends whose scatter is
  // atomic, the device's). The kinematics pass of one step reads only the nodal velocities,
  // and P2G writes only the nodal mass, momentum and force, so the step can zero those once
  // the velocities are formed and let each point, right after its own kinematics, add its
  // P2G of the next step: the same values into the same sums as the next step's P2G pass
  // would add (the next P2G reads no time step, and of the settings only the gravity may
  // change), without that pass reading the points again. The caller asks for it only where
  // nothing reads or changes the grid or the points between the two steps other than a
  // re-sort (a permutation of the points leaves the sums as they are): not before an output
  // of the grid, a change of the grid's nodes, points added or removed by the host.
  // explicit_step throws std::invalid_argument where it cannot fuse: pressure averaging, held
  // points, affine transfers, USF, or a backend whose scatter is not atomic (the CPU's).
  // On an H100 it made P1's step slower (0.91x at 12.8M points; doc/performance.md), so
  // DeviceEngine does not use it; p1_benchmark --fused measures it.
  template <int dim, typename Real>
  struct FusedTransfer
  {
    bool carry_next        = false; // in: this step's kinematics also runs the next step's P2G
    Real next_gravity[dim] = {};    // in: the next step's gravity (with its ramp)
    bool p2g_carried       = false; // in/out: this step's P2G ran in the last step; set by the step
  };
} // namespace mpm
