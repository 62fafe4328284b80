// Field output (grid nodes and material points as .vtu/.pvtu with .pvd time series)
// and the time history (history.csv), written once in parallel.
//
// The particle files are written from a snapshot of the engine's arrays (Engine::snapshot),
// not from the ParticleHandler: no hand-over, no re-sort per output. Their content is what
// deal.II's Particles::DataOut writes for the handler (same names, components, values;
// tests/dealii/test_output_paths.cc asserts it). What the files show is copied when the output
// is asked for (the snapshot, the nodal vectors; the CUDA engine's points may still be
// coming down, and the particle task waits for them); building the patches, compressing and
// writing can then run on two background threads (grid, particles) while the steps go on
// (Output/Write in background). The DoFHandler is read there as it is: a repartition must
// call finish() first.
#pragma once

#include <mpm/core/diagnostics.h>
#include <mpm/dealii/background_grid.h>
#include <mpm/dealii/material_points.h>
#include <mpm/dealii/output_settings.h>

#include <deal.II/base/data_out_base.h>

#include <atomic>
#include <fstream>
#include <future>
#include <memory>
#include <string>
#include <utility>
#include <vector>

namespace mpm
{
  // deal.II's Particles::DataOut layout from a snapshot: one patch per point (points that
  // left the grid skipped), data "id" then every property of PropertyLayout by name, with
  // the same vector ranges.
  template <int dim>
  class PointDataOut : public dealii::DataOutInterface<0, dim>
  {
  public:
    // Only these fields (PropertyLayout::fields; Output/Particle fields) after the id; empty:
    // every property. Call before build_patches.
    void select_fields(const std::vector<std::string> &fields) { selected_fields = fields; }
    // Patches of the snapshot's points begin .. end - 1 (end < 0: to the last point).
    void build_patches(const PointSnapshot<dim> &snapshot, int begin = 0, int end = -1);

  protected:
    const std::vector<dealii::DataOutBase::Patch<0, dim>> &get_patches() const override { return patches; }
    std::vector<std::string>                               get_dataset_names() const override;
    std::vector<std::tuple<unsigned int, unsigned int, std::string,
                           dealii::DataComponentInterpretation::DataComponentInterpretation>>
    get_nonscalar_data_ranges() const override;

  private:
    std::vector<dealii::DataOutBase::Patch<0, dim>> patches;
    std::vector<std::string>                        state_variable_names; // of the snapshot
    PointFieldSet                                   carried;              // the snapshot's fields
    std::vector<std::string>                        selected_fields;
    std::vector<unsigned int>                       components; // the properties written, in order
  };

  // What the grid files show, copied when the output is asked for (MPI collective: the
  // ghost values are updated): this rank's locally owned cells, ghosted copies of the nodal
  // mass and velocity, and the rank as cell data.
  template <int dim>
  struct GridSnapshot
  {
    GridSnapshot(const BackgroundGrid<dim> &grid, unsigned int rank);

    // One rank with Grid/Nodes = near material, where deal.II's grid of the box is not built:
    // the engine's lattice cells with mass at a vertex (Engine::cells_with_mass), each given by
    // its lower corner and its vertices' fields.
    struct LatticeCells
    {
      double                              h = 0;
      std::vector<dealii::Point<dim>>     lower_corner;
      // Per cell, per vertex in deal.II's order (x fastest), the nodal mass then velocity.
      std::vector<double>                 vertex_values;
    };
    explicit GridSnapshot(LatticeCells cells);

    std::vector<typename dealii::DoFHandler<dim>::active_cell_iterator> cells;
    std::vector<typename BackgroundGrid<dim>::Vector>                   nodal; // mass, velocity_x, ...
    LatticeCells                                                         lattice_cells; // used where cells is empty
    float                                                                rank = 0;
    // Grid/Cells per deal.II cell k > 1: a patch per lattice cell of each deal.II cell, its
    // vertices' values found through the grid's lattice lookup of the snapshot's time.
    int                                        cells_per_grid_cell = 1;
    std::shared_ptr<const LatticeNodeMap<dim>> lattice_to_node;
    double                                     origin[dim] = {}, h = 0;

    int n_cells() const
    {
      return static_cast<int>(cells.empty() ? lattice_cells.lower_corner.size() :
                                              cells.size() * dealii::Utilities::pow(cells_per_grid_cell, dim));
    }
  };

  // The cells of a grid that keeps only the nodes near the material (`nodes`: its
  // numbering, mass and velocity; lattice_of_node the lattice index of each node, -1 for
  // none) with mass at a vertex, in lattice order, and their vertices' mass and velocity
  // (vertices not kept: zero). Real: the nodes' type (float with Backend/Precision = float);
  // the cells' corners come from the lattice's origin and cell size in double.
  template <int dim, typename Real>
  typename GridSnapshot<dim>::LatticeCells lattice_cells_with_mass(const GridView<dim, Real> &nodes,
                                                                   const std::vector<long>    &lattice_of_node,
                                                                   const double origin[dim], double h);

  // The patches deal.II's DataOut<dim> builds for the grid's Q1 fields (one per cell: its
  // vertices, each nodal field's values at them, "subdomain" as cell data), made straight
  // from the vertex DoFs: for Q1 a field's value at a vertex is that vertex's DoF value.
  // DataOut::build_patches evaluates FEValues per cell instead: 0.8 s per output of P2's
  // 230,400 cells on the development VM, the longest of the output tasks.
  // tests/dealii/test_output_paths.cc asserts the same file as DataOut's.
  template <int dim>
  class GridDataOut : public dealii::DataOutInterface<dim, dim>
  {
  public:
    // Patches of the snapshot's cells begin .. end - 1 (end < 0: to the last cell).
    void build_patches(const GridSnapshot<dim> &snapshot, int begin = 0, int end = -1);

  protected:
    const std::vector<dealii::DataOutBase::Patch<dim, dim>> &get_patches() const override { return patches; }
    std::vector<std::string>                                 get_dataset_names() const override;

  private:
    std::vector<dealii::DataOutBase::Patch<dim, dim>> patches;
  };

  template <int dim>
  class OutputWriter
  {
  public:
    // yield_to_steps: the background writers run at a lower priority (nice 10), so that they do
    // not take the core of the thread that queues the steps (Backend = cuda). resuming: the run
    // continues a checkpoint (resume() follows); history.csv's rows are kept.
    OutputWriter(const OutputSettings &settings, bool yield_to_steps, MPI_Comm communicator, bool resuming = false);

    // What a checkpoint keeps of the output: outputs written and the .pvd records.
    struct Records
    {
      unsigned int                                 n_outputs = 0;
      std::vector<std::pair<double, std::string>> grid, particles;
    };
    Records records() const { return {counter, grid_records, particle_records}; }
    // A run resumed at `step` with the records of its checkpoint: later files number on
    // from there, and history.csv keeps its rows up to that step (rows of steps after it,
    // written before the run was stopped, are dropped: the resumed run writes them again).
    void resume(const Records &records, long step);
    // Waits for a write in flight; an error there is reported by finish(), not here.
    ~OutputWriter();

    // The snapshot the next write_fields() writes: fill it (Engine::snapshot, or
    // Engine::start_snapshot: the particle task waits for the points) right before. Waits
    // for the write in flight that still reads it.
    PointSnapshot<dim> &next_snapshot();

    // Writes grid and particle files for time t (rank 0 writes the .pvtu and .pvd records,
    // every rank its own .vtu pieces: Output/Files per rank, written on as many threads)
    // from the grid's nodal vectors and next_snapshot().
    // With Output/Write particle table, also particle_table_NNNNN.R.csv per rank R: id,
    // position and every property in full precision (the .vtu files hold single
    // precision). Copies the nodal vectors (with their ghosts: MPI) before returning; the
    // rest may still be running on background threads when it returns.
    void write_fields(double time, BackgroundGrid<dim> &grid);
    // The same without deal.II's grid (one rank, Grid/Nodes = near material): the grid files
    // show the engine's cells with mass.
    void write_fields(double time, typename GridSnapshot<dim>::LatticeCells cells);

    // Waits for the writes in flight and rethrows their error, if any. Call it before the
    // triangulation or the DoFHandler change (repartition).
    void finish();

    struct HistoryRow
    {
      double                   time, dt, work_of_gravity;
      long                     step, n_removed;
      PointTotals<dim, double> totals; // already summed over ranks
      // Parallel bookkeeping: fewest and most points on one rank, re-sorts of the points
      // into cells and ranks, repartitions of the grid, points handed to another rank.
      long min_points_per_rank = 0, max_points_per_rank = 0, n_resorts = 0, n_repartitions = 0, n_sent = 0;
      // The loss checks: mass of the points removed so far (left the grid), and (mass in the
      // grid + removed mass - initial mass) / initial mass.
      double removed_mass = 0, mass_balance = 0;
    };
    void write_history(const HistoryRow &row);

    const std::string &directory() const { return output_directory; }

    // Outputs written so far, seconds spent in the write tasks (building patches,
    // compressing, writing; summed over tasks, on background threads where they ran
    // there) and seconds the run waited for them in finish().
    unsigned int n_outputs() const { return counter; }
    double       task_seconds() const { return 1e-9 * task_nanoseconds; }
    double       waited_seconds() const { return waited; }

    // Files in the output directory in this writer's naming that this run did not write:
    // outputs numbered from n_outputs() on, and kinds of file this run does not write
    // (an earlier, longer run's, or one with other Output/Write settings). They are in no
    // .pvd record of this run, but a script or a file dialog would still find them.
    // Sorted; empty on ranks other than 0.
    std::vector<std::string> files_of_earlier_runs() const;

  private:
    // Writes the files of time t from the grid's snapshot (null: no grid files) and the
    // points' (next_snapshot), on background threads where asked.
    void write(double time, std::shared_ptr<const GridSnapshot<dim>> grid_snapshot);

    MPI_Comm                          communicator;
    unsigned int                      rank, n_ranks;
    std::string                       output_directory;
    bool                              write_grid, write_particles, write_table, background;
    std::vector<std::string>          particle_fields; // empty: all
    unsigned int                      pieces_per_rank; // .vtu files per rank and output
    bool                              yield_to_steps; // Backend = cuda: background threads at a lower priority
    dealii::DataOutBase::VtkFlags     vtk_flags;
    unsigned int                      counter = 0;
    std::vector<std::pair<double, std::string>> grid_records, particle_records;
    std::ofstream                     history;
    PointSnapshot<dim>                snapshot;
    std::vector<std::future<void>>    in_flight; // grid and particle tasks
    std::atomic<long long>            task_nanoseconds{0};
    double                            waited = 0;
  };
} // namespace mpm
