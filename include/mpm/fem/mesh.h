// The FEM stage's mesh, as Pre-failure analysis/Mesh asks: the prm's one body meshed with
// quadrilaterals (hexahedra in 3D), or a mesh file read by deal.II's GridIn; refined
// globally; material ids and boundary ids set (prefailure_parameters.h says which).
#pragma once

#include <mpm/fem/fem_material.h>
#include <mpm/fem/prefailure_scene.h>

#include <deal.II/distributed/tria.h>
#include <deal.II/grid/tria.h>

#include <array>
#include <map>
#include <vector>

namespace mpm::fem
{
  // Boundary id of the faces of a generated mesh that lie on no plane of its bounding box.
  constexpr unsigned int other_boundary_id = 6;

  // A polygon in (horizontal, vertical) coordinates meshed into `mesh` with cells of at most
  // about cell_size: as columns (the polygon between a bottom and a top profile over x,
  // vertical mesh lines) where it can be, else as rows (between a left and a right profile
  // over the height); the polygon's vertices are mesh vertices. Throws if neither fits (a
  // polygon whose vertical or horizontal cuts are not single intervals of positive length).
  void mesh_polygon(const std::vector<std::array<double, 2>> &polygon, double cell_size, dealii::Triangulation<2> &mesh);

  // Boundary ids 2d / 2d+1 on faces lying on the bounding box's planes min / max of axis d,
  // other_boundary_id elsewhere.
  template <int dim>
  void set_bounding_box_boundary_ids(dealii::Triangulation<dim> &mesh);

  // Fills the (empty) triangulation and returns the materials of its material ids.
  template <int dim>
  std::map<dealii::types::material_id, FemMaterial> create_mesh(const PrefailureScene &scene,
                                                                dealii::parallel::distributed::Triangulation<dim> &triangulation);
} // namespace mpm::fem
