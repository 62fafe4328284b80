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
#include <mpm/core/stencil_contribution.h>
#include <mpm/core/material/material.h>
#include <mpm/core/prefetch.h>
#include <mpm/core/shape_functions.h>
#include <mpm/core/small_tensor.h>
#include <mpm/core/views.h>
#include <mpm/core/wall_friction.h>

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
      if (m.elastic_law == ElasticLaw::hencky || m.model == MaterialModel::mohr_coulomb)
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

  // Hooks between a P2G pass and the nodal update, where ranks sum their ghost
  // contributions (deal.II's Partitioner import/export in the deal.II layer). The core needs none.
  // sum_cells: the same for the per-cell sums of the pressure averaging (arrays over
  // lattice cells), between their scatter and their gather.
  struct NoGridExchange
  {
    template <typename Real>
    void sum_nodal(Real *const *, int) const
    {}
    template <typename Real>
    void sum_cells(Real *const *, int) const
    {}
  };

  // Exchanges that overlap the sums with work (the device's on several ranks) also have
  //   int  points_before_overlap() : how many leading points can add into exchanged entries
  //                                  (exchange_overlap.h), -1 where they do not overlap now;
  //   void begin_sum(ExchangedEntries, arrays, count) : starts the sum of what the work so far
  //                                  added (the leading points' pass);
  //   void end_sum(ExchangedEntries) : the sums are in the arrays for the work after it.
  enum class ExchangedEntries
  {
    nodes,
    cells
  };
  template <typename Exchange, typename = void>
  struct overlaps_exchange : std::false_type
  {};
  template <typename Exchange>
  struct overlaps_exchange<Exchange, std::void_t<decltype(std::declval<const Exchange &>().points_before_overlap())>>
    : std::true_type
  {};

  // Backends whose scatters run in parallel by colouring (CpuBackend) declare
  // `static constexpr bool colours_scatter = true` and group the points first.
  template <typename Backend, typename = void>
  struct colours_scatter : std::false_type
  {};
  template <typename Backend>
  struct colours_scatter<Backend, std::void_t<decltype(Backend::colours_scatter)>>
    : std::bool_constant<Backend::colours_scatter>
  {};

  // Backends whose add_to_node is atomic, so that a gather loop may also scatter into
  // cells (CudaBackend); the others scatter only inside scatter_points.
  template <typename Backend, typename = void>
  struct atomic_scatter : std::false_type
  {};
  template <typename Backend>
  struct atomic_scatter<Backend, std::void_t<decltype(Backend::atomic_scatter)>>
    : std::bool_constant<Backend::atomic_scatter>
  {};

  // Host backends that lend per-point scratch memory kept between steps
  // (CpuBackend::point_scratch(n, bytes per point)).
  template <typename Backend, typename = void>
  struct has_point_scratch : std::false_type
  {};
  template <typename Backend>
  struct has_point_scratch<Backend, std::void_t<decltype(std::declval<Backend &>().point_scratch(0, 0))>>
    : std::true_type
  {};

  // A point's domain as the stencil reads it (domain_values<dim, Shape>() values): the
  // current half-lengths for the tensor-product shapes; CPDI's R = F R_0 (cpdi.h), R_0 the
  // initial half-lengths on the diagonal, from the point's F of the step's start; CPDI2q's
  // corner offsets q_c = R_0 s_c + delta_c, delta_c from the state variables.
  template <int dim, typename Shape, typename Real>
  MPM_HOST_DEVICE inline void load_domain(const PointsView<dim, Real> &p, const StepSettings<dim, Real> &s,
                                          const int i, Real *domain)
  {
    if constexpr (Shape::tensor_product)
      for (int d = 0; d < dim; ++d)
        domain[d] = p.domain_half_length[d][i];
    else if constexpr (Shape::tracks_corners)
      for (int c = 0; c < (1 << dim); ++c)
        for (int d = 0; d < dim; ++d)
          domain[c * dim + d] = ((c >> d) & 1 ? p.initial_domain_half_length[d][i] :
                                                -p.initial_domain_half_length[d][i]) +
                                p.state_variables[s.corner_state_variable + c * dim + d][i];
    else
      for (int a = 0; a < dim; ++a)
        for (int b = 0; b < dim; ++b)
          domain[a * dim + b] = p.deformation_gradient[a * dim + b][i] * p.initial_domain_half_length[b][i];
  }

  namespace stages
  {
    // For colouring backends: group the points by the first lattice layer of their
    // stencil along the longest grid axis, before the scatters of a point
    // configuration (again whenever the points have moved; the CPU backend keeps its
    // slabs while every point stays within their margin, checked each time). A point's
    // scatters write nodes of layers [first, first + n_per_direction - 1] and its own
    // cell, which lies in that range too. Other backends (CUDA: atomics) need nothing.
    template <int dim, typename Shape, typename Real, typename Backend>
    void group_for_scatter(Backend &backend, const GridView<dim, Real> &g, const PointsView<dim, Real> &p,
                           const StepSettings<dim, Real> &s)
    {
      if constexpr (colours_scatter<Backend>::value)
        {
          int axis = 0;
          for (int d = 1; d < dim; ++d)
            if (g.n_cells[d] > g.n_cells[axis])
              axis = d;
          // The key is the lowest layer the point writes: its stencil's first node, computed
          // with the stencil's own arithmetic (for_each_stencil_node), or its cell (pressure
          // averaging: GridView::lattice_cell's arithmetic) where round-off at a cell face
          // puts that one lower. GIMP: the cell always lies in [first, first + 2] (s is at
          // least half a cell above the first node), so the key is first and the span 3.
          // Linear: the cell can be first - 1 at a face, so the span is 3, not 2.
          if constexpr (!Shape::tensor_product)
            {
              // CPDI: from the lowest layer its corners' cells write (or its own cell) to the
              // highest; the span is the widest of all points now (a domain stretched over
              // several cells writes several layers).
              auto layers = [&](const int i, int &lo, int &hi) {
                Real x[dim], domain[domain_values<dim, Shape>()];
                for (int d = 0; d < dim; ++d)
                  x[d] = p.position[d][i];
                load_domain<dim, Shape>(p, s, i, domain);
                cpdi_layers<dim, Shape>(g.origin[axis], g.h, g.n_cells[axis], x[axis], domain, axis, lo, hi);
                int cell = static_cast<int>(std::floor((x[axis] - g.origin[axis]) / g.h));
                cell     = cell < 0 ? 0 : (cell >= g.n_cells[axis] ? g.n_cells[axis] - 1 : cell);
                lo       = cell < lo ? cell : lo;
                hi       = cell + 1 > hi ? cell + 1 : hi;
              };
              int span = 3;
              for (int i = 0; i < p.n_points; ++i)
                if (p.material[i] >= 0)
                  {
                    int lo, hi;
                    layers(i, lo, hi);
                    span = hi - lo + 1 > span ? hi - lo + 1 : span;
                  }
              backend.group_points(p.n_points, g.n_cells[axis] + 1, span, [&](const int i) {
                if (p.material[i] < 0)
                  return -1;
                int lo, hi;
                layers(i, lo, hi);
                return lo;
              });
              return;
            }
          else
            {
              constexpr int n    = Shape::n_per_direction;
              constexpr int span = n == 2 ? 3 : n;
              const Real    inv_h = Real(1) / g.h;
              backend.group_points(p.n_points, g.n_cells[axis] + 1, span, [&](const int i) {
                if (p.material[i] < 0)
                  return -1;
                int        first;
                Real       w[n], dw[n];
                const Real x = p.position[axis][i];
                Shape::weights_1d((x - g.origin[axis]) * inv_h, p.domain_half_length[axis][i] * inv_h, first, w, dw);
                int cell = static_cast<int>(std::floor((x - g.origin[axis]) / g.h));
                cell     = cell < 0 ? 0 : (cell >= g.n_cells[axis] ? g.n_cells[axis] - 1 : cell);
                const int key = first < cell ? first : cell;
                return key < 0 ? 0 : key;
              });
            }
        }
    }

    // Number of the pressure averaging's cell sums a node loop zeroes along the way (0
    // unless cells_too), checking that the grid has them.
    template <int dim, typename Real>
    int cell_sums_to_zero(const GridView<dim, Real> &g, const bool cells_too)
    {
      if (cells_too && (g.cell_volume == nullptr || g.cell_pressure_volume == nullptr))
        throw std::invalid_argument("pressure averaging needs GridView::cell_volume and cell_pressure_volume");
      return !cells_too ? 0 : g.cell_sums_at_nodes ? g.n_nodes : g.n_lattice_cells();
    }

    // Item n of a node loop over max(n_nodes, n_cells) items: zeroes cell n's sums where
    // n < n_cells; returns whether n is a node.
    template <int dim, typename Real>
    MPM_HOST_DEVICE inline bool zero_cell_sums_then_is_node(const GridView<dim, Real> &g, const int n,
                                                             const int n_cells)
    {
      if (n < n_cells)
        {
          g.cell_volume[n]          = Real(0);
          g.cell_pressure_volume[n] = Real(0);
        }
      return n < g.n_nodes;
    }

    // A loop over n_items node (and cell) indices, or over the grid's node list where it has
    // one (GridView::node_list: host backends; the cell sums then sit at the nodes).
    template <int dim, typename Real, typename Backend, typename F>
    void for_each_grid_node(Backend &backend, const GridView<dim, Real> &g, const int n_items, F &&f)
    {
      if constexpr (!atomic_scatter<Backend>::value)
        if (g.node_list != nullptr)
          {
            if (n_items > g.n_nodes)
              throw std::invalid_argument("GridView::node_list needs the cell sums at the nodes (cell_sums_at_nodes)");
            const int *list = g.node_list;
            backend.for_each_node(g.n_listed, [&](const int k) { f(list[k]); });
            return;
          }
      backend.for_each_node(n_items, std::forward<F>(f));
    }

    // Nodal sums to zero before a P2G pass; with cells_too also the pressure averaging's
    // cell sums, in the same pass (one launch less on the device).
    template <int dim, typename Real, typename Backend>
    void reset_grid(Backend &backend, const GridView<dim, Real> &g, const bool mass_too, const bool cells_too = false)
    {
      const int n_cells = cell_sums_to_zero(g, cells_too);
      for_each_grid_node(backend, g, g.n_nodes > n_cells ? g.n_nodes : n_cells, [=] MPM_HOST_DEVICE(const int n) {
        if (!zero_cell_sums_then_is_node(g, n, n_cells))
          return;
        if (mass_too)
          g.mass[n] = Real(0);
        for (int d = 0; d < dim; ++d)
          {
            g.momentum[d][n] = Real(0);
            g.force[d][n]    = Real(0);
          }
      });
    }

    // The pressure averaging's shift of the normal stresses s_xx, s_yy, s_zz of a point at
    // x: its cell's volume-weighted mean stress (summed by scatter_cell_pressure) minus
    // the point's own (plane strain: sigma_zz included).
    template <typename Real>
    MPM_HOST_DEVICE inline Real mean_normal_stress(const Real s_xx, const Real s_yy, const Real s_zz)
    {
      return (s_xx + s_yy + s_zz) / Real(3);
    }
    template <int dim, typename Real>
    MPM_HOST_DEVICE inline Real cell_pressure_shift(const GridView<dim, Real> &g, const Real x[dim], const Real s_xx,
                                                    const Real s_yy, const Real s_zz)
    {
      const Real mean = mean_normal_stress(s_xx, s_yy, s_zz);
      const int  c    = g.cell_sum_entry(x);
      if (c < 0) // a cell whose sums are not kept (nodes near the material: the run stops after the step)
        return Real(0);
      return g.cell_pressure_volume[c] / g.cell_volume[c] - mean;
    }

    // Whether point i (not removed) takes part in the pressure averaging: not where it is
    // disconnected (material.h), since a point that has lost contact has no pressure to share
    // and takes none. disconnecting: the materials, or null where none disconnects
    // (StepSettings::disconnected_points).
    template <int dim, typename Real>
    MPM_HOST_DEVICE inline bool averages_pressure(const MaterialParameters<Real> *disconnecting,
                                                  const PointsView<dim, Real> &p, const int i)
    {
      return disconnecting == nullptr ||
             !disconnected(disconnecting[p.material[i]], p.volume[i] / p.initial_volume[i]);
    }
    template <int dim, typename Real>
    inline const MaterialParameters<Real> *disconnecting_materials(const StepSettings<dim, Real> &s,
                                                                   const MaterialParameters<Real> *materials)
    {
      return s.disconnected_points ? materials : nullptr;
    }

    // APIC's D_p / h^2 for a shape function (Jiang et al. 2015), 0 where it has none constant.
    template <typename Shape>
    MPM_HOST_DEVICE constexpr double apic_inertia_over_h2()
    {
      if constexpr (std::is_same_v<Shape, QuadraticBSplineShape>)
        return 0.25;
      else if constexpr (std::is_same_v<Shape, CubicBSplineShape>)
        return 1.0 / 3.0;
      else
        return 0;
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

    // Grid update: local damping (local_damping.h), boundary masks, explicit
    // momentum update. Leaves v^{n+1} in velocity[], p^{n+1} in momentum[] (or zero where
    // the next stage rebuilds the momentum from the points: MUSL's remap, one pass over
    // the nodes less), and in force[] the nodal part of the blended G2P velocity,
    //   w = alpha dt a + (1 - alpha) v^{n+1}   (alpha = FLIP fraction, a = f / m),
    // so that G2P gathers one nodal vector instead of two (updated_point_velocity).
    template <int dim, typename Real, typename Backend>
    void update_grid(Backend &backend, const GridView<dim, Real> &g, const StepSettings<dim, Real> &s,
                     const Real dt_given, const bool zero_momentum = false, const bool zero_cells = false)
    {
      // zero_cells: also the pressure averaging's cell sums, which this step's P2G has
      // just applied (explicit_step's deferred averaging), in the same launch.
      const int n_cells = cell_sums_to_zero(g, zero_cells);
      for_each_grid_node(backend, g, g.n_nodes > n_cells ? g.n_nodes : n_cells, [=] MPM_HOST_DEVICE(const int n) {
        if (!zero_cell_sums_then_is_node(g, n, n_cells))
          return;
        const Real dt = time_step_of(s, dt_given);
        const Real m  = g.mass[n];
        // The force-norm form sees the whole force, the components a boundary holds fixed
        // included (read only for that form: the default reads nothing more).
        Real norm = Real(0);
        if (s.damping_form == LocalDampingForm::force_norm)
          {
            Real f[dim];
            for (int d = 0; d < dim; ++d)
              f[d] = g.force[d][n];
            norm = local_damping_norm<dim>(f, s.damping_form);
          }
        // A node on a frictional wall keeps its velocity before the update, from which the
        // wall's correction of the new velocity gives the acceleration FLIP needs.
        const std::uint8_t faces = g.friction_faces != nullptr && m > s.mass_tolerance ? g.friction_faces[n] : 0;
        // The node's velocity before the update: from the points' momentum, or with the
        // points held the grid's own of the last held step.
        const bool grid_velocity = s.hold_points && !s.hold_from_point_momentum;
        const auto velocity_before = [&](const int d) {
          return grid_velocity ? g.velocity[d][n] : g.momentum[d][n] / m;
        };
        Real v_old[dim];
        if (faces != 0)
          for (int d = 0; d < dim; ++d)
            v_old[d] = (g.fixed_components[n] >> d) & 1u && !s.flip_fixed_velocity_change ? Real(0)
                                                                                           : velocity_before(d);
        for (int d = 0; d < dim; ++d)
          {
            const bool fixed = (g.fixed_components[n] >> d) & 1u;
            if (m <= s.mass_tolerance || fixed)
              {
                // FLIP's share of the boundary's change to zero (PIC's share is zero).
                g.force[d][n] = m > s.mass_tolerance && s.flip_fixed_velocity_change
                                  ? -s.flip_fraction * velocity_before(d)
                                  : Real(0);
                g.momentum[d][n] = g.velocity[d][n] = Real(0);
                continue;
              }
            const Real v     = velocity_before(d);
            const Real f     = damped_force_component(g.force[d][n], v, norm, s.damping, s.damping_form,
                                                      s.damping_threshold);
            // (Two forms, so that the points' path keeps its rounding.)
            const Real p_new = grid_velocity ? m * (v + dt * (f / m)) : g.momentum[d][n] + dt * f;
            const Real v_new = grid_velocity ? v + dt * (f / m) : p_new / m;
            g.momentum[d][n] = zero_momentum ? Real(0) : p_new;
            g.velocity[d][n] = v_new;
            g.force[d][n]    = s.flip_fraction * (dt * (f / m)) + (Real(1) - s.flip_fraction) * v_new;
          }
        if (faces != 0)
          {
            Real v[dim];
            for (int d = 0; d < dim; ++d)
              v[d] = g.velocity[d][n];
            apply_wall_friction<dim>(v, faces, g.friction_coefficient);
            for (int d = 0; d < dim; ++d)
              {
                g.momentum[d][n] = zero_momentum ? Real(0) : m * v[d];
                g.velocity[d][n] = v[d];
                g.force[d][n]    = s.flip_fraction * (v[d] - v_old[d]) + (Real(1) - s.flip_fraction) * v[d];
              }
          }
      });
    }

    // Nodal velocity from nodal momentum, boundary masks re-imposed; on a frictional wall
    // only the contact (the friction acted in the grid update, and the remap carries it).
    template <int dim, typename Real, typename Backend>
    void velocity_from_momentum(Backend &backend, const GridView<dim, Real> &g, const Real mass_tolerance)
    {
      for_each_grid_node(backend, g, g.n_nodes, [=] MPM_HOST_DEVICE(const int n) {
        const Real m = g.mass[n];
        Real       v[dim];
        for (int d = 0; d < dim; ++d)
          {
            const bool fixed = (g.fixed_components[n] >> d) & 1u;
            v[d]             = (m <= mass_tolerance || fixed) ? Real(0) : g.momentum[d][n] / m;
          }
        if (g.friction_faces != nullptr)
          apply_wall_contact<dim>(v, g.friction_faces[n]);
        for (int d = 0; d < dim; ++d)
          g.velocity[d][n] = v[d];
      });
    }

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

    // Lattice cell of point i and its mean stress tr(sigma)/3 (plane strain: sigma_zz
    // included), for both passes of the pressure averaging.
    template <int dim, typename Real>
    MPM_HOST_DEVICE inline int cell_and_mean_stress(const GridView<dim, Real> &g, const PointsView<dim, Real> &p,
                                                    const int i, Real &mean)
    {
      Real x[dim];
      for (int d = 0; d < dim; ++d)
        x[d] = p.position[d][i];
      mean = mean_normal_stress(p.stress[0][i], p.stress[1][i], p.stress[2][i]);
      return g.cell_sum_entry(x);
    }

    // The first pass of the averaging for point i (not removed): V_p and V_p p_p into its
    // cell's sums.
    template <typename Backend, int dim, typename Real>
    MPM_HOST_DEVICE inline void add_cell_pressure(const GridView<dim, Real> &g, const PointsView<dim, Real> &p,
                                                  const int i, const MaterialParameters<Real> *disconnecting)
    {
      if (!averages_pressure(disconnecting, p, i))
        return;
      Real        mean;
      const int   c          = cell_and_mean_stress(g, p, i, mean);
      if (c < 0) // a cell whose sums are not kept (nodes near the material: the run stops after the step)
        return;
      const Real  V          = p.volume[i];
      Real *const targets[2] = {g.cell_volume, g.cell_pressure_volume};
      const Real  values[2]  = {V, V * mean};
      Backend::template add_to_node<2>(targets, c, values);
    }

    // The same from a per-point loop other than scatter_points: only where add_to_node is
    // atomic (grid_to_particle_kinematics refuses the others before it starts), and not in the
    // fused kinematics (compiled = false), which the averaging does not run with: on the device
    // add_to_node's staging area and the stencil scatter's records do not fit one kernel.
    template <typename Backend, bool compiled = true, int dim, typename Real>
    MPM_HOST_DEVICE inline void add_cell_pressure_atomically(const GridView<dim, Real> &g,
                                                             const PointsView<dim, Real> &p, const int i,
                                                             const MaterialParameters<Real> *disconnecting)
    {
      if constexpr (atomic_scatter<Backend>::value && compiled)
        add_cell_pressure<Backend>(g, p, i, disconnecting);
      else
        {
          (void)g, (void)p, (void)i, (void)disconnecting;
        }
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

    // pass(points) over every point, then the sum of the arrays over the ranks. Where the
    // exchange overlaps (n_first >= 0), the first n_first points (those that can add into
    // exchanged entries) go first, the sum starts, and the other points' pass runs while the
    // sums travel: they add into no exchanged entry, so the sums and the step are the same.
    template <typename Exchange, int dim, typename Real, typename Pass, typename Sum>
    void pass_then_sum(const Exchange &exchange, const int n_first, const PointsView<dim, Real> &p, Pass &&pass,
                       const ExchangedEntries entries, Real *const *arrays, const int count, Sum &&sum)
    {
      (void)n_first;
      if constexpr (overlaps_exchange<Exchange>::value)
        if (n_first >= 0 && n_first <= p.n_points)
          {
            pass(point_range(p, 0, n_first));
            exchange.begin_sum(entries, arrays, count);
            pass(point_range(p, n_first, p.n_points - n_first));
            exchange.end_sum(entries);
            return;
          }
      pass(p);
      sum();
    }

    // exchange.sum_cells if the exchange has one; exchanges for one rank only (the CUDA
    // engine's nodal adapter) may have none.
    template <typename Exchange, typename Real>
    auto sum_cells(const Exchange &exchange, Real *const *arrays, const int count, int)
      -> decltype(exchange.sum_cells(arrays, count), void())
    {
      exchange.sum_cells(arrays, count);
    }
    template <typename Exchange, typename Real>
    void sum_cells(const Exchange &, Real *const *, const int, long)
    {}

    // Cell pressure averaging (against volumetric locking, as in ep2-3De): every point
    // of a lattice cell gets the volume-weighted mean pressure of the cell,
    //   p_c = sum_p V_p p_p / sum_p V_p,   sigma_p <- s_p - p_c I   (s_p deviatoric part kept),
    // with p = -tr(sigma)/3 (plane strain: sigma_zz included). Two passes through the
    // backend: scatter V_p and V_p p_p into per-cell sums (zeroed by reset_grid, or by
    // update_grid after a P2G that applied a deferred averaging), then gather p_c back
    // (apply_cell_pressure: by itself, inside the step's reduction, or in the next P2G). The averaged stress is not returned to the yield surface again
    // (ep2-3De neither). On several ranks, exchange.sum_cells sums the cells between the
    // two passes.
    template <int dim, typename Real, typename Backend, typename Exchange = NoGridExchange>
    void scatter_cell_pressure(Backend &backend, const GridView<dim, Real> &g, const PointsView<dim, Real> &p,
                               const Exchange &exchange = Exchange(),
                               const MaterialParameters<Real> *disconnecting = nullptr)
    {
      if (g.cell_volume == nullptr || g.cell_pressure_volume == nullptr)
        throw std::invalid_argument("pressure averaging needs GridView::cell_volume and cell_pressure_volume");
      backend.scatter_points(p.n_points, [=] MPM_HOST_DEVICE(const int i) {
        if (p.material[i] >= 0)
          add_cell_pressure<Backend>(g, p, i, disconnecting);
      });
      // MPI: a cell near a partition boundary holds points of two ranks (a point that has
      // not migrated yet sits less than a cell outside its home cell): sum over ranks.
      Real *cell_sums[2] = {g.cell_volume, g.cell_pressure_volume};
      sum_cells(exchange, cell_sums, 2, 0);
    }

    // The gather of the averaging for point i (not removed).
    template <int dim, typename Real>
    MPM_HOST_DEVICE inline void apply_cell_pressure(const GridView<dim, Real> &g, const PointsView<dim, Real> &p,
                                                    const int i, const MaterialParameters<Real> *disconnecting)
    {
      if (!averages_pressure(disconnecting, p, i))
        return;
      Real x[dim];
      for (int d = 0; d < dim; ++d)
        x[d] = p.position[d][i];
      const Real shift = cell_pressure_shift(g, x, p.stress[0][i], p.stress[1][i], p.stress[2][i]);
      for (int k = 0; k < 3; ++k)
        p.stress[k][i] += shift;
    }

    // The averaging's gather over every point: the second pass of average_cell_pressure,
    // and a pending one (explicit_step's deferred averaging) before the stresses are read
    // outside the step.
    template <int dim, typename Real, typename Backend>
    void finish_pressure_averaging(Backend &backend, const GridView<dim, Real> &g, const PointsView<dim, Real> &p,
                                   const MaterialParameters<Real> *disconnecting = nullptr)
    {
      backend.template gather_points<Real>(p.n_points, [=] MPM_HOST_DEVICE(const int i) {
        if (p.material[i] >= 0)
          apply_cell_pressure(g, p, i, disconnecting);
      });
    }

    // Both passes, cell sums zeroed first (USF, whose averaging is not the step's last pass).
    template <int dim, typename Real, typename Backend, typename Exchange = NoGridExchange>
    void average_cell_pressure(Backend &backend, const GridView<dim, Real> &g, const PointsView<dim, Real> &p,
                               const Exchange &exchange = Exchange(),
                               const MaterialParameters<Real> *disconnecting = nullptr)
    {
      const int n_cells = cell_sums_to_zero(g, true);
      for_each_grid_node(backend, g, n_cells, [=] MPM_HOST_DEVICE(const int c) { zero_cell_sums_then_is_node(g, c, n_cells); });
      scatter_cell_pressure(backend, g, p, exchange, disconnecting);
      finish_pressure_averaging(backend, g, p, disconnecting);
    }

    // The step's reductions (largest speed, power of gravity). With apply_averaging, the
    // same pass first gathers the cell pressure back into each point (reduce_points calls
    // the per-point function exactly once per point): one pass over the points less.
    template <int dim, typename Real, typename Backend>
    StepReduction<Real> reduce_step(Backend &backend, const GridView<dim, Real> &g, const PointsView<dim, Real> &p,
                                    const StepSettings<dim, Real> &s, const bool apply_averaging = false,
                                    const MaterialParameters<Real> *disconnecting = nullptr)
    {
      StepReduction<Real> init{Real(0), Real(0), Real(0)};
      return backend.reduce_points(
        p.n_points, init,
        [=] MPM_HOST_DEVICE(const int i) {
          if (apply_averaging && p.material[i] >= 0)
            apply_cell_pressure(g, p, i, disconnecting);
          StepReduction<Real> r{Real(0), Real(0), Real(0)};
          Real v2 = Real(0);
          for (int d = 0; d < dim; ++d)
            v2 += p.velocity[d][i] * p.velocity[d][i];
          if (p.material[i] < 0)
            {
              r.max_removed_speed = std::sqrt(v2);
              return r;
            }
          for (int d = 0; d < dim; ++d)
            r.gravity_power += p.mass[i] * s.gravity[d] * p.velocity[d][i];
          r.max_speed = std::sqrt(v2);
          return r;
        },
        // A speed that is not a number wins the maximum (a != a): a blow-up cannot hide behind
        // the order in which the threads combine.
        [] MPM_HOST_DEVICE(const StepReduction<Real> &a, const StepReduction<Real> &b) {
          return StepReduction<Real>{a.max_speed > b.max_speed || a.max_speed != a.max_speed ? a.max_speed :
                                                                                                b.max_speed,
                                     a.gravity_power + b.gravity_power,
                                     a.max_removed_speed > b.max_removed_speed ||
                                         a.max_removed_speed != a.max_removed_speed ?
                                       a.max_removed_speed :
                                       b.max_removed_speed};
        });
    }
  } // namespace stages

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
        if (s.affine_matrix == AffineMatrix::b_d_inverse && apic_inertia_over_h2<Shape>() == 0 &&
            !std::is_same_v<Shape, LinearShape>)
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
    if (shape == ShapeFunction::gimp)
      return explicit_step<dim, GimpShape, physics>(backend, g, p, materials, s, dt, exchange,
                                                    averaging_pending, fused);
    if (shape == ShapeFunction::bspline2)
      return explicit_step<dim, QuadraticBSplineShape, physics>(backend, g, p, materials, s, dt, exchange,
                                                                averaging_pending, fused);
    if (shape == ShapeFunction::bspline3)
      return explicit_step<dim, CubicBSplineShape, physics>(backend, g, p, materials, s, dt, exchange,
                                                            averaging_pending, fused);
    if (shape == ShapeFunction::bspline3_gimp)
      return explicit_step<dim, CubicBSplineGimpShape, physics>(backend, g, p, materials, s, dt, exchange,
                                                                averaging_pending, fused);
    if (shape == ShapeFunction::cpdi)
      return explicit_step<dim, CpdiShape, physics>(backend, g, p, materials, s, dt, exchange,
                                                    averaging_pending, fused);
    if (shape == ShapeFunction::cpdi2q)
      {
        if constexpr (dim == 2)
          return explicit_step<dim, Cpdi2qShape, physics>(backend, g, p, materials, s, dt, exchange,
                                                          averaging_pending, fused);
        else
          throw std::invalid_argument("explicit_step: CPDI2q is two-dimensional");
      }
    return explicit_step<dim, LinearShape, physics>(backend, g, p, materials, s, dt, exchange,
                                                    averaging_pending, fused);
  }
} // namespace mpm
