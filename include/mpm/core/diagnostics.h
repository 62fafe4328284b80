// Totals over the material points for the time history: mass, kinetic energy,
// linear momentum, number of points and bounding box of the material; and the number and
// mass of the points marked as having left the grid that the arrays still hold (the loss
// checks count them with those already dropped).
#pragma once

#include <mpm/core/views.h>

namespace mpm
{
  template <int dim, typename Real>
  struct PointTotals
  {
    Real mass;
    Real kinetic_energy;
    Real momentum[dim];
    Real lower[dim], upper[dim];
    long n_points;
    Real removed_mass; // points with material < 0, still held
    long n_removed;
  };

  // Sum: the type the totals are summed in (Real, or double for a float engine's points).
  template <int dim, typename Real, typename Backend, typename Sum = Real>
  PointTotals<dim, Sum> point_totals(Backend &backend, const PointsView<dim, Real> &p)
  {
    PointTotals<dim, Sum> identity;
    identity.mass = identity.kinetic_energy = identity.removed_mass = Sum(0);
    identity.n_points = identity.n_removed = 0;
    for (int d = 0; d < dim; ++d)
      {
        identity.momentum[d] = Sum(0);
        identity.lower[d]    = Sum(1e300);
        identity.upper[d]    = Sum(-1e300);
      }
    return backend.reduce_points(
      p.n_points, identity,
      [=] MPM_HOST_DEVICE(const int i) {
        PointTotals<dim, Sum> t    = identity;
        const Sum             mass = p.mass[i];
        if (p.material[i] < 0)
          {
            t.removed_mass = mass;
            t.n_removed    = 1;
            return t;
          }
        t.mass     = mass;
        t.n_points = 1;
        for (int d = 0; d < dim; ++d)
          {
            const Sum v = p.velocity[d][i];
            t.kinetic_energy += Sum(0.5) * mass * v * v;
            t.momentum[d] = mass * v;
            t.lower[d] = t.upper[d] = p.position[d][i];
          }
        return t;
      },
      [] MPM_HOST_DEVICE(const PointTotals<dim, Sum> &a, const PointTotals<dim, Sum> &b) {
        PointTotals<dim, Sum> r;
        r.mass           = a.mass + b.mass;
        r.kinetic_energy = a.kinetic_energy + b.kinetic_energy;
        r.n_points       = a.n_points + b.n_points;
        r.removed_mass   = a.removed_mass + b.removed_mass;
        r.n_removed      = a.n_removed + b.n_removed;
        for (int d = 0; d < dim; ++d)
          {
            r.momentum[d] = a.momentum[d] + b.momentum[d];
            r.lower[d]    = a.lower[d] < b.lower[d] ? a.lower[d] : b.lower[d];
            r.upper[d]    = a.upper[d] > b.upper[d] ? a.upper[d] : b.upper[d];
          }
        return r;
      });
  }
} // namespace mpm
