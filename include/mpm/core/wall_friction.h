// Coulomb friction of the grid's rigid walls on the nodes that lie on them (doc/theory.md,
// "Frictional walls"). After the grid update a wall node's velocity v is the velocity the
// node would have without the wall. Where the node moves into the wall (v_n > 0, v_n the
// component along the wall's outward normal), the wall
//   - removes v_n, a normal impulse m v_n;
//   - and reduces the tangential velocity v_t by mu v_n along its own direction, to rest at
//     most (never reversed): |v_t| <- max(0, |v_t| - mu v_n).
// Where it moves away (v_n <= 0) nothing presses on the wall: the material separates and the
// node is left alone. (A wall that also held departing nodes, as a free-slip wall does, would
// turn velocity noise at the wall into normal impulse one way only, and so into friction:
// 17% too much braking of a sliding block with MUSL and FLIP, doc/log.md.)
// A node on several frictional faces (an edge, a corner) meets them one after the other.
// Every wall, frictional or not, also stops the points' centres (stop_at_walls).
#pragma once

#include <mpm/core/config.h>

#include <cmath>
#include <cstdint>

namespace mpm
{
  // Face f of the grid: axis f / 2, the lower (f even) or upper (f odd) end; its outward
  // normal is -e_axis or +e_axis. Bit f of a node's friction mask: the node lies on face f.
  template <int dim>
  constexpr int n_grid_faces = 2 * dim;

  // Velocity of a node into face f (positive towards the outside of the grid).
  template <typename Real>
  MPM_HOST_DEVICE inline Real velocity_into_face(const Real *v, const int face)
  {
    return face % 2 ? v[face / 2] : -v[face / 2];
  }

  // The normal part alone, for velocities the friction has already acted on (MUSL's
  // remapped nodal velocity, USF's velocity before the update): a node moving into a face
  // of its mask loses that component.
  template <int dim, typename Real>
  MPM_HOST_DEVICE inline void apply_wall_contact(Real v[dim], const std::uint8_t faces)
  {
    for (int face = 0; face < n_grid_faces<dim>; ++face)
      if (((faces >> face) & 1u) && velocity_into_face(v, face) > Real(0))
        v[face / 2] = Real(0);
  }

  // A rigid wall (no-slip, free-slip or friction) holds the nodes on it, but a point's centre
  // moves with every node of its stencil: with GIMP or B-spline weights a point near the wall
  // still follows the nodes one and two cells inside, so a flow pressing on a wall can carry
  // centres through it (under a granular flow's front on a frictional floor, doc/theory.md).
  // For a point whose new position x (in place) is outside the grid: each coordinate beyond a
  // face of `walls` (bit f: face f, x min, x max, y min, ...) stops on that face. Returns
  // whether the point is inside the grid now (false where it left through a free face, or x is
  // not a number). The kinematics calls it only for points outside, after its own test.
  template <int dim, typename Real>
  MPM_HOST_DEVICE inline bool stop_at_walls(const std::uint8_t walls, const Real origin[dim], const Real h,
                                            const int n_cells[dim], Real x[dim])
  {
    bool inside = true;
    for (int d = 0; d < dim; ++d)
      {
        const Real s = (x[d] - origin[d]) / h;
        if (((walls >> (2 * d)) & 1u) && s < Real(0))
          x[d] = origin[d];
        else if (((walls >> (2 * d + 1)) & 1u) && s > Real(n_cells[d]))
          x[d] = origin[d] + Real(n_cells[d]) * h;
        else if (!(s >= Real(0) && s <= Real(n_cells[d])))
          inside = false;
      }
    return inside;
  }

  // v: a node's velocity after the grid update, in place; faces: its friction mask;
  // coefficient[f]: the friction coefficient mu of face f.
  template <int dim, typename Real>
  MPM_HOST_DEVICE inline void apply_wall_friction(Real v[dim], const std::uint8_t faces,
                                                  const Real coefficient[n_grid_faces<dim>])
  {
    for (int face = 0; face < n_grid_faces<dim>; ++face)
      {
        if (!((faces >> face) & 1u))
          continue;
        const Real into = velocity_into_face(v, face);
        if (!(into > Real(0)))
          continue;
        v[face / 2] = Real(0);
        Real tangential = Real(0);
        for (int d = 0; d < dim; ++d)
          tangential += v[d] * v[d];
        tangential = std::sqrt(tangential);
        if (!(tangential > Real(0)))
          continue;
        const Real kept  = Real(1) - coefficient[face] * into / tangential;
        const Real scale = kept > Real(0) ? kept : Real(0);
        for (int d = 0; d < dim; ++d)
          v[d] *= scale;
      }
  }
} // namespace mpm
