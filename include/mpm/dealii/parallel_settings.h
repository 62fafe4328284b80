// Subsection Parallel of the parameter file: how an MPI run re-sorts its points into cells and
// ranks and balances the ranks' work (doc/performance.md, MPI).
#pragma once

#include <deal.II/base/parameter_handler.h>

namespace mpm
{
  struct ParallelSettings
  {
    double resort_distance;        // re-sort at this fraction of the safe distance outside a home cell
    double load_balance_threshold; // repartition when max/mean work per rank exceeds it; 0 = never
    double point_weight;           // work of one point relative to one empty cell

    // Declares the entries of subsection Parallel (prm inside it).
    static void declare(dealii::ParameterHandler &prm);
    // Reads them (prm inside subsection Parallel); throws naming the entry on bad input.
    void parse(dealii::ParameterHandler &prm);
  };
} // namespace mpm
