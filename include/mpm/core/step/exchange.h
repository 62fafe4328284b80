// The hooks where MPI ranks sum their ghost contributions between the stages (NoGridExchange for
// one rank), and the passes that overlap those sums with work.
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

  namespace stages
  {
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
  } // namespace stages
} // namespace mpm
