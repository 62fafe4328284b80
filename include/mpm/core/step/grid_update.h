// The grid's stages: grouping the points for colouring scatters, zeroing the nodal sums, the nodal
// update (damping, boundary masks, momentum, the FLIP blend) and the velocity from the remapped momentum.
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
#include <mpm/core/step/exchange.h>
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
  } // namespace stages
} // namespace mpm
