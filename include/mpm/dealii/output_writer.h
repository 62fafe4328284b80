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

    // Writes grid and particle files for time t and updates the .pvd records.
    void write_fields(double time, BackgroundGrid<dim> &grid, const MaterialPoints<dim> &points);

    struct HistoryRow
    {
      double                   time, dt, work_of_gravity;
      long                     step, n_removed;
      PointTotals<dim, double> totals; // already summed over ranks
    };
    void write_history(const HistoryRow &row);

    const std::string &directory() const { return output_directory; }

  private:
    MPI_Comm    communicator;
    std::string output_directory;
    bool        write_grid, write_particles;
    unsigned int counter = 0;
    std::vector<std::pair<double, std::string>> grid_records, particle_records;
    std::ofstream history;
  };
} // namespace mpm
