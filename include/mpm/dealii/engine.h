// Where the MPM step runs. The simulator hands points over at the start and takes
// them back (store) only when the ParticleHandler must see them (MPI re-sort and
// repartition); in between, the engine keeps them in the backend's arrays. Output reads
// a snapshot of those arrays instead, with no hand-over.
//
// On one rank an engine keeps its own nodes on the lattice (lattice_grid) and starts
// from the generated bodies: it needs neither deal.II's grid nor the handler, which are
// built beside the first steps. On several ranks the nodes are the BackgroundGrid's
// ghosted vectors, summed over ranks after each scatter. CPU here; the CUDA engine
// (cuda_engine.h) implements the same interface over device arrays, one GPU per rank.
#pragma once

#include <mpm/core/active_nodes.h>
#include <mpm/core/diagnostics.h>
#include <mpm/core/step.h>
#include <mpm/core/time_step_rule.h>
#include <mpm/dealii/material_points.h>
#include <mpm/dealii/output_writer.h>

#include <limits>
#include <memory>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <vector>

namespace mpm
{
  // Runs choose(), a choice of the nodes near the points with Grid/Active block size =
  // block_cells, and returns what it returns. Where the nodes it would keep are more than an
  // int counts (std::length_error from the core's NodeBlockChooser or the device engine), throws
  // a deal.II ExcMessage naming that parameter and its allowed values instead.
  template <typename Choose>
  auto choose_nodes_near_material(const int block_cells, Choose &&choose) -> decltype(choose())
  {
    try
      {
        return choose();
      }
    catch (const std::length_error &)
      {
        AssertThrow(false, dealii::ExcMessage(
                             "Grid/Active block size = " + std::to_string(block_cells) +
                             ": the nodes kept near the material (whole blocks of that many nodes per axis around "
                             "every block of cells holding a point) are more than an int can count. Allowed values "
                             "are 1 to 64: choose a smaller block size."));
      }
    return choose(); // not reached: AssertThrow(false, ...) throws
  }

  // The loss checks' tolerance on the relative mass balance of an engine whose points are in
  // Real: the round-off of the mass sums, 1e-9 in double (their order differs from the initial
  // sum's), 1e-7 in float (each mass rounded once: within 2^-24 of its double, so are the sums).
  template <typename Real>
  constexpr double relative_mass_round_off_of()
  {
    return std::is_same_v<Real, double> ? 1e-9 : 1e-7;
  }

  template <int dim>
  class Engine
  {
  public:
    virtual ~Engine() = default;
    // The handler's points (MPI re-sorts and repartitions).
    virtual void load(const MaterialPoints<dim> &points) = 0;
    // Points given as arrays, with their labels in the same order (points_of_bodies).
    virtual void load(const HostPoints<dim, double> &points, std::shared_ptr<const PointLabels<dim>> labels) = 0;
    virtual unsigned int            store(MaterialPoints<dim> &points)                = 0;
    // The MPI re-sort: points that have moved into other ranks' cells go there, points
    // that left the grid are removed (their number on this rank is returned), and every
    // point's home cell becomes its current cell. By default through the handler (store);
    // an engine may move only the points that change rank and leave the handler behind
    // until sync().
    virtual unsigned int resort(MaterialPoints<dim> &points) { return store(points); }
    // Brings the handler up to date with the engine's points where resort() left it behind
    // (before a repartition, which moves the handler's points with their cells).
    virtual void sync(MaterialPoints<dim> & /*points*/) {}
    // Points the engine holds on this rank (those that left the grid may be counted until
    // the next re-sort).
    virtual long n_points() const = 0;
    virtual StepReduction<double>   step(const StepSettings<dim, double> &s, double dt) = 0;
    // One rank on the GPU (Backend/Queue steps): a step queued behind the last one without
    // waiting for it, its time step computed on the device by the host's rule
    // (time_step_rule.h) from the last queued step's largest speed, or with speed_from_host
    // from host_speed (the first step queued after anything else). collect_step() waits for
    // the oldest queued step and returns its reductions and time step; at most two may be
    // uncollected, and every one must be collected before anything else reads or changes
    // the points.
    virtual bool queues_steps() const { return false; }
    virtual void queue_step(const StepSettings<dim, double> & /*s*/, const TimeStepRule & /*rule*/, double /*time*/,
                            double /*next_output*/, bool /*speed_from_host*/, double /*host_speed*/)
    {
      AssertThrow(false, dealii::ExcMessage("Internal: this engine does not queue steps."));
    }
    virtual QueuedStep collect_step()
    {
      AssertThrow(false, dealii::ExcMessage("Internal: this engine does not queue steps."));
      return {};
    }
    virtual PointTotals<dim, double> totals()                                         = 0;
    // For output: copies the points as they are now into snapshot.points (engine order,
    // points that left the grid included with material < 0) and sets snapshot.labels.
    // The handler is not touched.
    virtual void snapshot(PointSnapshot<dim> &snapshot) = 0;
    // The same, where the engine can, without waiting for the points: they arrive in
    // snapshot.wait_for_points(), which must run before they are read and before the next
    // snapshot into the same object. The CUDA engine's steps go on meanwhile.
    virtual void start_snapshot(PointSnapshot<dim> &snapshot) { this->snapshot(snapshot); }
    // For output: brings the grid's nodal vectors (mass, velocity) up to date where the
    // engine keeps its own nodes. Before the first step every nodal field is zero, in the
    // engine as in a grid just built.
    virtual void nodal_to(BackgroundGrid<dim> &grid) = 0;
    // Largest distance of a point outside the cell it was sorted into at the last
    // load/store, in cell units (max-norm); MPI runs re-sort before it gets unsafe.
    // An engine that does not track it makes MPI runs re-sort after every step.
    virtual double max_distance_outside_home_cells() { return std::numeric_limits<double>::infinity(); }
    // Seconds of the ghost-node exchanges so far as the device saw them (the GPU engine on
    // several ranks: from the end of the work before each exchange to its sums in place);
    // negative where the engine does not measure them.
    virtual double exchange_seconds() { return -1; }
    // Of those, the seconds the host spent in them (copies and MPI); negative where not measured.
    virtual double exchange_host_seconds() { return -1; }
    // The GPU engine on several ranks: the mean share of the rank's points whose passes run
    // before each exchange (the others' run while it travels); negative where none overlap.
    virtual double share_of_points_before_overlap() { return -1; }
    // Steps between re-sorts of the points (Backend/Sort interval); engines that do not
    // re-sort ignore it.
    virtual void set_sort_interval(int /*steps*/) {}
    // Grid/Nodes = near material: one rank, the engine keeps only the nodes near the points
    // (active_nodes.h), and the run refreshes them (refresh_active_nodes) before a point gets
    // active_node_margin() cells out of the cell it was in at the last refresh; several ranks
    // (cpu), the step visits only those nodes of the rank's part of the grid. Loading points
    // refreshes them (on several ranks at every re-sort, well inside the margin).
    bool   follows_material() const { return near_material.block_cells > 0; }
    double active_node_margin() const
    {
      return follows_material() ? mpm::active_node_margin(near_material.shape, near_material.block_cells) : 0;
    }
    virtual void refresh_active_nodes() {}
    // For the grid output without deal.II's grid (one rank, nodes near the material): the
    // lattice cells with mass at a vertex, in lattice order, with their vertices' fields.
    virtual void cells_with_mass(typename GridSnapshot<dim>::LatticeCells & /*cells*/)
    {
      AssertThrow(false, dealii::ExcMessage("Internal: this engine keeps no nodes of its own to write."));
    }
    // Nodes the engine updates now, and the most it has had (nodes near the material; on
    // several ranks summed over the ranks, a node counted on each rank that holds it).
    long n_active_nodes() const { return near_material.now; }
    long most_nodes() const { return near_material.most; }
    // Of the choices of nodes near the material so far, those and how many were numbered as
    // the box around the material (the others through the block table).
    long node_choices() const { return near_material.choices; }
    long node_choices_as_box() const { return near_material.as_box; }
    // The loss checks' tolerance on the relative mass balance (relative_mass_round_off_of).
    virtual double relative_mass_round_off() const { return relative_mass_round_off_of<double>(); }
    // Replaces the material table (e.g. when plasticity is switched on).
    virtual void set_materials(const std::vector<MaterialParameters<double>> &materials) = 0;

  protected:
    // Nodes near the material: what the engine keeps between its choices of nodes.
    struct NearMaterialNodes
    {
      int                       block_cells = 0; // 0: every node
      ShapeFunction             shape       = ShapeFunction::gimp;
      long                      now = 0, most = 0;                                 // nodes kept
      long choices = 0, as_box = 0; // choices that kept nodes, and those numbered as a box (GPU)

      void kept(const long n, const bool box = false)
      {
        now  = n;
        most = n > most ? n : most;
        if (n > 0) // not the choice before any point is loaded
          {
            ++choices;
            as_box += box ? 1 : 0;
          }
      }
    };
    NearMaterialNodes near_material;
  };

  // Throws naming Backend/Backend where the backend is not in this build. The simulator
  // asks before any set-up.
  void check_backend(const std::string &backend);

  // One rank: the engine's own nodes on the lattice (lattice_grid: geometry and boundary
  // masks), all of them or, with active_block_cells > 0, those near the material in blocks
  // of that many cells per axis. Throws naming Backend/Backend if the requested backend is
  // not available. single_precision (Backend/Precision = float): the points, nodes and step
  // in float (either backend); built-in materials only.
  template <int dim>
  std::unique_ptr<Engine<dim>> make_engine(const std::string &backend, const HostGrid<dim, double> &lattice,
                                           const std::vector<MaterialParameters<double>> &materials,
                                           ShapeFunction shape, int active_block_cells = 0,
                                           bool single_precision = false);

  // Several ranks: the nodes are the grid's (cpu: its vectors, or in float the engine's own
  // arrays in their numbering; cuda: the device's copy of the rank's locally relevant nodes),
  // exchanged through the grid's partitioner. single_precision: cpu only. active_block_cells
  // > 0 (cpu): the step visits only the nodes near the material, in blocks of that many cells
  // (Grid/Nodes = near material); the arrays are those of the rank's fine cells
  // (BackgroundGrid::coarse_away_from_material).
  template <int dim>
  std::unique_ptr<Engine<dim>> make_engine(const std::string &backend, BackgroundGrid<dim> &grid,
                                           const std::vector<MaterialParameters<double>> &materials,
                                           ShapeFunction shape, bool single_precision = false,
                                           int active_block_cells = 0);
} // namespace mpm
