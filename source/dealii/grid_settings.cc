#include <mpm/dealii/grid_settings.h>
#include <mpm/dealii/parameter_error.h>
#include <mpm/dealii/prm_reading.h>

#include <deal.II/base/utilities.h>

#include <cmath>

namespace mpm
{
  using dealii::ParameterHandler;
  namespace Patterns = dealii::Patterns;
  using namespace prm_reading;

  void GridSettings::declare(ParameterHandler &prm, const unsigned int dim)
  {
    prm.enter_subsection("Grid");
    prm.declare_entry("Lower corner", zeros(dim), point_pattern(dim),
                      "Lower corner of the background grid, one coordinate per dimension (m).");
    prm.declare_entry("Upper corner", ones(dim), point_pattern(dim),
                      "Upper corner of the background grid (m). Each extent must be a multiple of the cell size.");
    prm.declare_entry("Cell size", "0.1", Patterns::Double(0),
                      "Edge length h of the square/cubic grid cells (m), the same in every direction.");
    prm.declare_entry("Nodes", "all", Patterns::Selection("all|near material"),
                      "Which nodes of the grid the step keeps and updates. all: every node of the box. near "
                      "material: only those of the blocks of Active block size^dim cells that hold a material "
                      "point or touch such a block, chosen again whenever a point has moved far enough to need "
                      "others; cost and memory then follow the material, not the box (the results are the same: "
                      "bit for bit on the CPU, to round-off on the GPU). The grid files then show only the cells "
                      "with mass, and on one rank deal.II's grid of the whole box is not built. The kept nodes are "
                      "numbered as the box around them where that box holds at most twice the kept blocks (no "
                      "lookup per node: as fast as every node of a box that size), else through a table with "
                      "one entry per block of nodes (no array over the whole box, so the box can be far larger "
                      "than the memory its nodes would take). On several ranks (Backend = cpu) deal.II's grid is "
                      "fine only within two blocks of the points (coarse elsewhere, refined as they spread), the "
                      "step visits only the kept nodes, and the partition weighs only the cells with points; "
                      "nothing is kept per cell of the box (about 6 bytes per block). With Backend = cuda on "
                      "several ranks each rank keeps every node of its part of the grid.");
    prm.declare_entry("Active block size", "4", Patterns::Integer(1, 64),
                      "Nodes = near material: edge of the blocks, in cells. Every cell within this many cells "
                      "of a point's cell is kept; larger blocks choose the nodes less often but keep more. The "
                      "cubic B-spline GIMP, whose stencil reaches two cells out, needs at least 2.");
    prm.declare_entry("Cells per deal.II cell", "1", Patterns::Integer(1, 16),
                      "Edge k of deal.II's cells of the background grid, in cells of Cell size: deal.II's grid has "
                      "k^dim times fewer cells, and its Q_k elements with equidistant nodes put a degree of "
                      "freedom at every node of the MPM grid, so the step, its nodes and its results are the "
                      "same. Building deal.II's grid (on several ranks before the first step) is then much "
                      "faster, and the partition among ranks moves whole deal.II cells. Each extent of the grid "
                      "must be a multiple of k cells.");
    prm.leave_subsection();

    prm.enter_subsection("Boundary conditions");
    for (unsigned int d = 0; d < dim; ++d)
      for (const std::string side : {"min", "max"})
        prm.declare_entry(std::string(axis_names[d]) + " " + side, "free",
                          Patterns::Selection("free|no-slip|free-slip|friction"),
                          std::string("Condition on the grid face ") + axis_names[d] + " = " + side +
                            " (boundary id " + std::to_string(2 * d + (side == std::string("max"))) +
                            "): free (points that cross it leave the grid and are removed), no-slip (all "
                            "velocity components zero), free-slip (roller: normal component zero) or friction "
                            "(a rigid wall with Coulomb friction, coefficient Friction coefficient: where "
                            "material presses on it, normal component zero and the tangential one braked; where "
                            "material moves away, nothing). The three walls also stop the points' centres "
                            "on the face.");
    prm.declare_entry("Friction coefficient", "0", Patterns::Double(0),
                      "Coulomb friction coefficient mu of every face set to friction: where material presses "
                      "on the wall, the tangential velocity of a wall node is reduced by mu times its normal "
                      "velocity into the wall, to rest at most. Must be > 0 where a face is friction "
                      "(for a wall without friction use free-slip).");
    prm.leave_subsection();
  }

  void GridSettings::parse(ParameterHandler &prm, const unsigned int dim)
  {
    prm.enter_subsection("Grid");
    lower     = get_point(prm, "Lower corner", "Grid/");
    upper     = get_point(prm, "Upper corner", "Grid/");
    cell_size = prm.get_double("Cell size");
    if (!(cell_size > 0))
      parameter_error("Grid/Cell size", "must be > 0, got " + prm.get("Cell size") + ".");
    for (unsigned int d = 0; d < dim; ++d)
      {
        if (!(upper[d] > lower[d]))
          parameter_error("Grid/Upper corner", std::string("must exceed Lower corner in ") + axis_names[d] + ".");
        const double n = (upper[d] - lower[d]) / cell_size;
        if (std::abs(n - std::round(n)) > 1e-8 * std::max(1.0, n))
          parameter_error("Grid/Cell size", std::string("the extent in ") + axis_names[d] + " (" +
                                   dealii::Utilities::to_string(upper[d] - lower[d]) +
                                   " m) is not a whole number of cells of size " + prm.get("Cell size") + ".");
      }
    active_block_cells = prm.get("Nodes") == "near material" ? prm.get_integer("Active block size") : 0;
    cells_per_grid_cell = prm.get_integer("Cells per deal.II cell");
    for (unsigned int d = 0; d < dim; ++d)
      {
        const long n = std::lround((upper[d] - lower[d]) / cell_size);
        if (n % cells_per_grid_cell != 0)
          parameter_error("Grid/Cells per deal.II cell",
               "must divide the number of cells along every direction; " + std::string(axis_names[d]) + " has " +
                 std::to_string(n) + " cells, not a multiple of " + std::to_string(cells_per_grid_cell) + ".");
      }
    prm.leave_subsection();

    prm.enter_subsection("Boundary conditions");
    for (unsigned int d = 0; d < dim; ++d)
      for (unsigned int side = 0; side < 2; ++side)
        {
          const std::string v = prm.get(std::string(axis_names[d]) + (side ? " max" : " min"));
          boundary[2 * d + side] = v == "no-slip"   ? BoundaryType::no_slip :
                                   v == "free-slip" ? BoundaryType::free_slip :
                                   v == "friction"  ? BoundaryType::friction :
                                                      BoundaryType::free;
        }
    friction_coefficient = prm.get_double("Friction coefficient");
    for (unsigned int id = 0; id < 2 * dim; ++id)
      if (boundary[id] == BoundaryType::friction && !(friction_coefficient > 0))
        parameter_error("Boundary conditions/Friction coefficient",
             std::string("must be > 0 where a face is friction (") + axis_names[id / 2] + (id % 2 ? " max" : " min") +
               " is); for a wall without friction set that face to free-slip.");
    prm.leave_subsection();
  }
} // namespace mpm
