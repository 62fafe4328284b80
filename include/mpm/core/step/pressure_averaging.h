// Cell-wise pressure averaging against volumetric locking: each point's mean stress replaced by its
// cell's volume-weighted mean (two passes: scatter into cell sums, gather back).
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
#include <mpm/core/step/grid_update.h>
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
  } // namespace stages
} // namespace mpm
