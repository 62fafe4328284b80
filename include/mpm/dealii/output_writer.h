// Field output (grid nodes and material points as .vtu/.pvtu with .pvd time series)
// and the time history (history.csv), written once in parallel.
#pragma once

#include <mpm/core/diagnostics.h>
#include <mpm/dealii/background_grid.h>
#include <mpm/dealii/material_points.h>

#include <fstream>
#include <string>
#include <utility>
#include <vector>

namespace mpm
{
  template <int dim>
  class OutputWriter
  {
  public:
    OutputWriter(const Parameters &parameters, MPI_Comm communicator);

    // Writes grid and particle files for time t and updates the .pvd records (rank 0
    // writes the .pvtu and .pvd records, every rank its own .vtu piece). With Output/Write
    // particle table, also particle_table_NNNNN.R.csv per rank R: id, position and every
    // property in full precision (the .vtu files hold single precision).
    void write_fields(double time, BackgroundGrid<dim> &grid, const MaterialPoints<dim> &points);

    struct HistoryRow
    {
      double                   time, dt, work_of_gravity;
      long                     step, n_removed;
      PointTotals<dim, double> totals; // already summed over ranks
      // Parallel bookkeeping: fewest and most points on one rank, re-sorts of the points
      // into cells and ranks, repartitions of the grid, points handed to another rank.
      long min_points_per_rank = 0, max_points_per_rank = 0, n_resorts = 0, n_repartitions = 0, n_sent = 0;
    };
    void write_history(const HistoryRow &row);

    const std::string &directory() const { return output_directory; }

  private:
    MPI_Comm    communicator;
    std::string output_directory;
    bool        write_grid, write_particles, write_table;
    unsigned int counter = 0;
    std::vector<std::pair<double, std::string>> grid_records, particle_records;
    std::ofstream history;
  };
} // namespace mpm
