// Pieces of the background grid's set-up shared by its source files (background_grid*.cc): the
// box of lattice entries a rank holds, and the friction test of the faces. Internal.
#pragma once

#include <mpm/dealii/grid_settings.h>

#include <algorithm>
#include <array>
#include <limits>

namespace mpm
{
  namespace grid_detail
  {
    inline bool has_friction_face(const std::array<BoundaryType, 6> &boundary)
    {
      return std::find(boundary.begin(), boundary.end(), BoundaryType::friction) != boundary.end();
    }

    // A box of lattice entries (cells or nodes, `extent` of them along each axis) and an
    // entry's index in it, x fastest: arrays over the box around what a rank holds, not over
    // the lattice, whose box may be mostly empty (Grid/Nodes = near material).
    template <int dim>
    struct LatticeBox
    {
      long lower[dim], upper[dim]; // inclusive; empty while lower > upper

      LatticeBox()
      {
        std::fill(lower, lower + dim, std::numeric_limits<long>::max());
        std::fill(upper, upper + dim, -1L);
      }
      static void coordinates(long entry, const long extent[dim], long idx[dim])
      {
        for (int d = 0; d < dim; ++d)
          {
            idx[d] = entry % extent[d];
            entry /= extent[d];
          }
      }
      void add_at(const long idx[dim])
      {
        for (int d = 0; d < dim; ++d)
          {
            lower[d] = std::min(lower[d], idx[d]);
            upper[d] = std::max(upper[d], idx[d]);
          }
      }
      void add(const long entry, const long extent[dim])
      {
        long idx[dim];
        coordinates(entry, extent, idx);
        add_at(idx);
      }
      // Grown by `by` entries on every side, within the lattice.
      void grow(const long by, const long extent[dim])
      {
        for (int d = 0; d < dim; ++d)
          if (lower[d] <= upper[d])
            {
              lower[d] = std::max(0L, lower[d] - by);
              upper[d] = std::min(extent[d] - 1, upper[d] + by);
            }
      }
      long along(const int d) const { return std::max(0L, upper[d] - lower[d] + 1); }
      long size() const
      {
        long n = 1;
        for (int d = 0; d < dim; ++d)
          n *= along(d);
        return n;
      }
      long index_at(const long idx[dim]) const
      {
        long index = 0;
        for (int d = dim - 1; d >= 0; --d)
          {
            if (idx[d] < lower[d] || idx[d] > upper[d])
              return -1;
            index = index * along(d) + idx[d] - lower[d];
          }
        return index;
      }
      // -1 outside the box.
      long index(const long entry, const long extent[dim]) const
      {
        long idx[dim];
        coordinates(entry, extent, idx);
        return index_at(idx);
      }
      // The part of the box of count[d] entries from first[d] inside this box; false if none.
      bool clip(long first[dim], long count[dim]) const
      {
        for (int d = 0; d < dim; ++d)
          {
            const long from = std::max(first[d], lower[d]), to = std::min(first[d] + count[d] - 1, upper[d]);
            if (from > to)
              return false;
            first[d] = from;
            count[d] = to - from + 1;
          }
        return true;
      }
    };

    template <int dim>
    void cell_extent(const int n_cells[dim], long extent[dim])
    {
      for (int d = 0; d < dim; ++d)
        extent[d] = n_cells[d];
    }
  } // namespace grid_detail
} // namespace mpm
