// Grid and Boundary conditions: the background grid's box and cells, which nodes the step keeps,
// deal.II's cells, and the condition on each face of the box.
#pragma once

#include <deal.II/base/parameter_handler.h>

#include <array>
#include <vector>

namespace mpm
{
  enum class BoundaryType
  {
    free,      // no constraint
    no_slip,   // every velocity component zero
    free_slip, // normal velocity component zero (roller)
    friction   // rigid wall with Coulomb friction, unilateral contact (wall_friction.h)
  };

  struct GridSettings
  {
    std::vector<double> lower, upper;
    double              cell_size;
    int                 active_block_cells  = 0; // Nodes = near material: block edge in cells; 0: all nodes
    int                 cells_per_grid_cell = 1; // edge of deal.II's cells in MPM cells
    std::array<BoundaryType, 6> boundary{};      // by boundary id: x min, x max, y min, y max, z min, z max
    double                      friction_coefficient = 0; // mu of every face of type friction

    // The subsections Grid and Boundary conditions (entered here).
    static void declare(dealii::ParameterHandler &prm, unsigned int dim);
    void        parse(dealii::ParameterHandler &prm, unsigned int dim);
  };
} // namespace mpm
