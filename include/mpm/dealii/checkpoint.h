// Checkpoints on disk: the whole state of a run at the end of one step, from which
// Simulator::resume continues it exactly (doc/checkpoints.md).
//
// One folder per checkpoint, checkpoint-NNNNNNNNN (NNNNNNNNN the step), in Checkpoint/Directory:
//   run.state    the run's counters, clock and output bookkeeping (rank 0; RunState)
//   points.R     rank R's material points in the engine's order, every field (PointSnapshot)
// Written as checkpoint-NNNNNNNNN.partial and renamed once every rank has written and synced
// its files: a folder without the suffix is complete. Files are boost binary archives
// (deal.II's serialization), readable on machines of the same architecture.
#pragma once

#include <mpm/dealii/background_grid.h>
#include <mpm/dealii/material_points.h>
#include <mpm/dealii/simulator.h>

#include <mpi.h>

#include <functional>
#include <string>
#include <utility>
#include <vector>

namespace mpm
{
  // Everything of a run between two steps besides its points and grid.
  struct RunState
  {
    // What the checkpoint was written by: checked against the run that resumes it.
    unsigned int             dim = 0, n_ranks = 0;
    std::vector<double>      lower, upper;
    double                   cell_size = 0;
    unsigned int             n_materials = 0;
    std::vector<std::string> state_variable_names;
    double                   strength_divisor = 1; // Parameters::strength_divisor

    // The simulated clock and what the next step's time step and checks depend on.
    double time = 0, dt = 0, max_speed = 0, max_removed_speed = 0, work_of_gravity = 0, elastic_wave_speed = 0,
           smallest_point_mass = 0, balanced = 1, next_output = 0;
    long step = 0, n_points_initial = 0, n_removed = 0, n_resorts = 0, n_repartitions = 0, n_sent = 0;
    // The loss checks: the initial mass, and the points dropped after leaving the grid.
    double initial_mass = 0, dropped_mass = 0;
    long   n_dropped    = 0;
    bool plastic = false;
    EquilibrationReport equilibration;

    // Output bookkeeping: outputs written, the .pvd records (time, file).
    unsigned int                                 n_outputs = 0;
    std::vector<std::pair<double, std::string>> grid_records, particle_records;

    template <class Archive>
    void serialize(Archive &archive, unsigned int version);
  };

  namespace checkpoint
  {
    // "checkpoint-000000123" for step 123.
    std::string folder_name(long step);

    // Writes a checkpoint of `state` and this rank's `points` into directory (created if
    // missing), collectively. Keeps the newest `keep` checkpoints there. Returns the
    // checkpoint's folder. Throws on every rank, naming Checkpoint/Directory, where a rank
    // cannot write.
    template <int dim>
    std::string write(const std::string &directory, const RunState &state, const PointSnapshot<dim> &points,
                      unsigned int keep, MPI_Comm communicator);

    // The checkpoint to resume from `path`: path itself where it is one, else the newest
    // complete checkpoint in it. Throws naming --resume where there is none.
    std::string find(const std::string &path);

    RunState read_state(const std::string &checkpoint);

    // The points of every rank that wrote the checkpoint, rank by rank in each one's order,
    // of which those for which keep(points, i) is true (a rank keeps those in its cells):
    // one file is read at a time, so a rank holds no more than one file beside its own.
    template <int dim>
    PointSnapshot<dim> read_points(const std::string &checkpoint, const RunState &state,
                                   const std::function<bool(const HostPoints<dim, double> &, int)> &keep);
  } // namespace checkpoint
} // namespace mpm
