// The boundary masks of a lattice node, from what each face of the lattice's box
// prescribes: computed per node where it is needed, so that a grid that keeps only the
// nodes near the material holds no array over the whole lattice.
#pragma once

#include <mpm/core/views.h>

#include <cstdint>
#include <vector>

namespace mpm
{
  // Per face id (x min, x max, y min, ...): the velocity components its nodes have fixed
  // (bit d) and whether it is a frictional wall.
  template <int dim>
  struct FaceConditions
  {
    std::uint8_t fixed[2 * dim]    = {};
    bool         friction[2 * dim] = {};

    bool any_friction() const
    {
      for (int f = 0; f < 2 * dim; ++f)
        if (friction[f])
          return true;
      return false;
    }
  };

  // Masks of lattice node idx (views.h): fixed components, the faces' union where the node
  // lies on several (edges, corners); friction bit f where it lies on frictional face f.
  template <int dim>
  inline void node_boundary_masks(const FaceConditions<dim> &faces, const int n_cells[dim], const int idx[dim],
                                  std::uint8_t &fixed, std::uint8_t &friction)
  {
    fixed    = 0;
    friction = 0;
    for (int d = 0; d < dim; ++d)
      for (const int f : {2 * d, 2 * d + 1})
        if (idx[d] == (f % 2 == 0 ? 0 : n_cells[d]))
          {
            fixed |= faces.fixed[f];
            if (faces.friction[f])
              friction |= std::uint8_t(1u << f);
          }
  }

  // The masks of kept nodes given by their lattice indices (-1: a node beyond the lattice,
  // masks 0): fixed gets one entry per node, friction one per node where a face is
  // frictional, else none (the grids' convention for "no frictional face").
  template <int dim>
  void kept_node_boundary_masks(const FaceConditions<dim> &faces, const int n_cells[dim],
                                const std::vector<long> &lattice_of_node, std::vector<std::uint8_t> &fixed,
                                std::vector<std::uint8_t> &friction)
  {
    const std::size_t n = lattice_of_node.size();
    fixed.assign(n, 0);
    friction.assign(faces.any_friction() ? n : 0, 0);
    for (std::size_t node = 0; node < n; ++node)
      if (lattice_of_node[node] >= 0)
        {
          int          idx[dim];
          std::uint8_t f = 0;
          lattice_node_coordinates<dim>(n_cells, lattice_of_node[node], idx);
          node_boundary_masks<dim>(faces, n_cells, idx, fixed[node], f);
          if (!friction.empty())
            friction[node] = f;
        }
  }
} // namespace mpm
