#include <mpm/dealii/parallel_settings.h>
#include <mpm/dealii/parameter_error.h>

#include <deal.II/base/exceptions.h>

#include <cstdlib>
#include <string>

namespace mpm
{
  using dealii::ParameterHandler;
  namespace Patterns = dealii::Patterns;

  void ParallelSettings::declare(ParameterHandler &prm)
  {
    prm.declare_entry("Re-sort distance", "1", Patterns::Double(0, 1),
                      "MPI runs: the points are re-sorted into cells and ranks (migrating to the rank owning their "
                      "new cell) as soon as one point is this fraction of the safe distance outside the cell it was "
                      "sorted into (the safe distance, half a cell for GIMP and one cell for linear shape functions, "
                      "keeps its stencil within the rank's nodes), and before a point could end the next step beyond "
                      "the rank's ghost cells (where the re-sort would not find it). 1 = only when needed, 0 = every "
                      "step. With Solver/Pressure averaging, at most half a cell (the cell sums cover the ghost "
                      "cells).");
    prm.declare_entry("Load balance threshold", "1.1", Patterns::Double(0),
                      "MPI runs: the grid is repartitioned by work (cells weighted by their points) when the largest "
                      "work of one rank exceeds this multiple of the mean; checked at the start and after each "
                      "re-sort. 0 = never repartition; otherwise at least 1.");
    prm.declare_entry("Point weight", "20", Patterns::Double(0),
                      "MPI runs: work of one material point relative to one empty grid cell, for the weighted "
                      "partition (a cell weighs 1 + Point weight x its points; with Grid/Nodes = near material "
                      "and Backend = cpu a cell without points weighs nothing, since the step does not visit "
                      "its nodes).");
  }

  void ParallelSettings::parse(ParameterHandler &prm)
  {
    resort_distance        = prm.get_double("Re-sort distance");
    load_balance_threshold = prm.get_double("Load balance threshold");
    point_weight           = prm.get_double("Point weight");
    if (load_balance_threshold > 0 && load_balance_threshold < 1)
      parameter_error("Parallel/Load balance threshold", "must be 0 (never repartition) or at least 1, got " +
                                                 prm.get("Load balance threshold") + ".");
  }
} // namespace mpm
