// How far a point has moved out of its "home" cell, the cell it was sorted into when
// the deal.II layer last handed the points to the backend. In parallel runs the
// owning rank has every node of a point's stencil only while the point is less than
// a shape-dependent distance outside its home cell (half a cell for GIMP, one cell
// for linear, none for the cubic B-spline; doc/performance.md, MPI); the step loop re-sorts the points into cells
// and ranks before any point gets that far.
#pragma once

#include <mpm/core/shape/shape_family.h>
#include <mpm/core/views.h>

namespace mpm
{
  // Largest distance outside its home cell, in cell units and max-norm, such that
  // the point's stencil still lies in the home cell's vertices and the ring of
  // nodes around them (the vertices of the home cell's neighbours).
  inline double safe_distance_outside_home_cell(const ShapeFunction shape)
  {
    // Each member's own (shape_traits.h): linear's stencil starts at floor(s), two nodes: 1;
    // GIMP and the quadratic B-spline at floor(s + 1/2) - 1, three nodes: 1/2; the cubic
    // B-spline at floor(s) - 1, four nodes: 0, so the point must stay in its home cell.
    double distance = 0;
    with_shape(shape, [&](auto member) { distance = decltype(member)::safe_distance_outside_home_cell; });
    return distance;
  }

  // Distance of point i outside its home cell (0 inside), in cell units, max-norm.
  // home_cell is the lattice cell index i + n_x (j + n_y k).
  template <int dim, typename Real>
  MPM_HOST_DEVICE inline Real distance_outside_home_cell(const Real origin[dim], const Real h,
                                                         const int n_cells[dim], const Real *const position[dim],
                                                         const long home_cell, const int i)
  {
    // In int: the lattice's cells are counted in int (GridView::lattice_cell), and a 64-bit
    // division is several times the work of a 32-bit one on a GPU (this runs per point and step).
    int  c        = static_cast<int>(home_cell);
    Real distance = Real(0);
    for (int d = 0; d < dim; ++d)
      {
        const int lower = c % n_cells[d];
        c /= n_cells[d];
        const Real s       = (position[d][i] - origin[d]) / h - Real(lower);
        const Real outside = s < Real(0) ? -s : (s > Real(1) ? s - Real(1) : Real(0));
        distance           = outside > distance ? outside : distance;
      }
    return distance;
  }
} // namespace mpm
