// Fill a region of the grid with material points on a regular sub-lattice:
// n points per direction per cell, each owning an equal share of the cell.
#pragma once

#include <mpm/core/host_storage.h>

#include <cmath>
#include <vector>

namespace mpm
{
  template <int dim, typename Real>
  struct BodyDescription
  {
    int  points_per_direction;
    Real density;
    Real velocity[dim];
    int  material;
  };

  // Point-in-polygon by ray crossing (2D, vertices in order, either orientation).
  template <typename Real>
  bool inside_polygon(const std::vector<Real> &xs, const std::vector<Real> &ys, const Real x, const Real y)
  {
    bool         inside = false;
    const size_t n      = xs.size();
    for (size_t i = 0, j = n - 1; i < n; j = i++)
      if (((ys[i] > y) != (ys[j] > y)) && (x < (xs[j] - xs[i]) * (y - ys[i]) / (ys[j] - ys[i]) + xs[i]))
        inside = !inside;
    return inside;
  }

  // Adds the points of every cell sub-lattice site for which inside(x) holds, for the
  // cells overlapping [lower, upper]. Returns the number of points added.
  template <int dim, typename Real, typename Inside>
  int add_points(HostPoints<dim, Real> &points, const HostGrid<dim, Real> &grid, const Real lower[dim],
                 const Real upper[dim], const BodyDescription<dim, Real> &body, Inside &&inside)
  {
    const int  n  = body.points_per_direction;
    const Real dx = grid.h / n;
    int        first[dim], last[dim];
    long       count = 1;
    for (int d = 0; d < dim; ++d)
      {
        first[d] = static_cast<int>(std::floor((lower[d] - grid.origin[d]) / dx));
        last[d]  = static_cast<int>(std::ceil((upper[d] - grid.origin[d]) / dx));
        if (first[d] < 0)
          first[d] = 0;
        if (last[d] > grid.n_cells[d] * n)
          last[d] = grid.n_cells[d] * n;
        count *= (last[d] > first[d] ? last[d] - first[d] : 0);
      }
    // The sites inside first, then every point array resized once (one resize per point
    // of about 40 arrays took 0.2 s for P2's 512,000 points).
    std::vector<Real> sites;
    for (long k = 0; k < count; ++k)
      {
        long rest = k;
        Real x[dim];
        for (int d = 0; d < dim; ++d)
          {
            const int span = last[d] - first[d];
            x[d]           = grid.origin[d] + (first[d] + rest % span + Real(0.5)) * dx;
            rest /= span;
          }
        bool in_box = true;
        for (int d = 0; d < dim; ++d)
          in_box = in_box && x[d] > lower[d] && x[d] < upper[d];
        if (in_box && inside(x))
          sites.insert(sites.end(), x, x + dim);
      }
    const int added = static_cast<int>(sites.size() / dim);
    const int start = points.size();
    points.resize(start + added);
    const Real V = std::pow(dx, dim);
    for (int j = 0; j < added; ++j)
      {
        const int i = start + j;
        for (int d = 0; d < dim; ++d)
          {
            points.position[d][i]                   = sites[j * dim + d];
            points.velocity[d][i]                   = body.velocity[d];
            points.domain_half_length[d][i]         = Real(0.5) * dx;
            points.initial_domain_half_length[d][i] = Real(0.5) * dx;
          }
        for (int c = 0; c < n_voigt; ++c)
          points.stress[c][i] = points.strain[c][i] = Real(0);
        points.volume[i] = points.initial_volume[i] = V;
        points.mass[i]                              = body.density * V;
        points.plastic_strain[i]                    = Real(0);
        points.material[i]                          = body.material;
      }
    return added;
  }
} // namespace mpm
