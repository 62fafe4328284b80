// The whole explicit step on a CUDA device, behind a plain C++ interface that host
// code compiled by an ordinary C++ compiler can use: no CUDA and no deal.II header
// here. The implementation (source/cuda/device_engine/, one file per job, compiled by nvcc into the
// static library mpm_cuda_engine) keeps the points and nodes in device memory for
// the whole run; data crosses to the host only in upload/download (output, end of
// run, MPI migration), as the few bytes of each step's reduction and, on several MPI
// ranks, as the ghost entries of the nodal exchange.
//
// The host grid description is a GridView<dim, double> whose geometry, lattice
// lookup (lattice_to_node) and boundary masks (fixed_components) are read once at
// construction; nodal arrays are written only by download_nodal().
#pragma once

#include <mpm/core/diagnostics.h>
#include <mpm/core/host_storage.h>
#include <mpm/core/material/material.h>
#include <mpm/core/shape/shape_family.h>
#include <mpm/core/step.h>
#include <mpm/core/time_step_rule.h>
#include <mpm/core/views.h>

#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

namespace mpm
{
  namespace cuda
  {
    // Number of CUDA devices usable by this process (0 where there is none or no
    // driver); on 0, `why` says what the runtime reported.
    int device_count(std::string *why = nullptr);

    // Creates the CUDA context of the current device now (driver load and context: a few
    // tenths of a second), so that a thread can do it while the host builds the grid.
    // Errors are left for the engine's constructor to report.
    void initialise_device();

    // Name, compute capability and memory of the current device, for the log.
    std::string device_description();

    // Node-local rank -> device: the rank's GPU is (node-local rank) modulo the number of
    // devices; makes it the current device of the calling thread (every thread that uses
    // the engine, and the one that creates the context, must call it). Returns the device.
    int use_device_of_local_rank(int node_local_rank);

    // Where ranks sum their ghost contributions (several MPI ranks; null on one). The device
    // packs the entries that the exchange touches (ghost nodes and the owned nodes that
    // other ranks hold as ghosts) into pinned host memory, the host side sums them over the
    // ranks there (deal.II's Partitioner import/export), the device unpacks the sums. Only
    // those entries cross the PCIe bus, not the whole nodal arrays.
    class NodalExchange
    {
    public:
      virtual ~NodalExchange() = default;
      // Node indices (the host grid's numbering) that sum_nodal reads and writes.
      virtual std::vector<int> exchanged_nodes() const = 0;
      // values[j * count + k] is array k at exchanged_nodes()[j] (entry by entry); on
      // return, the sums over the ranks. In the engine's type: float engines call the
      // float overloads.
      virtual void sum_nodal(double *values, int count) = 0;
      virtual void sum_nodal(float *values, int count)  = 0;
      // The same for the pressure averaging's cell arrays, indexed by lattice cell.
      virtual std::vector<long> exchanged_cells() const = 0;
      virtual void              sum_cells(double *values, int count) = 0;
      virtual void              sum_cells(float *values, int count)  = 0;
    };

    // Whether the engines on several ranks overlap the exchange with the passes of the points
    // that cannot reach it (DeviceEngine::share_of_points_before_overlap): yes unless the
    // environment sets MPM_CUDA_OVERLAP=0 (for before/after timings in one build).
    bool exchange_overlap_enabled();

    // Real: the type the device keeps the points and nodes in and steps in: double, or float
    // for Backend/Precision = float. The interface is in double either way: points, settings,
    // materials, nodal fields and the step's reduction are converted where they cross it, and
    // totals() sums in double. On several ranks the ghost entries are exchanged in Real;
    // the points that change rank and their labels cross in double.
    template <int dim, typename Real = double>
    class DeviceEngine
    {
    public:
      // exchange: null on one rank (no ghost nodes).
      DeviceEngine(const GridView<dim, double> &host_grid, const std::vector<MaterialParameters<double>> &materials,
                   ShapeFunction shape, NodalExchange *exchange = nullptr);
      ~DeviceEngine();
      DeviceEngine(const DeviceEngine &)            = delete;
      DeviceEngine &operator=(const DeviceEngine &) = delete;

      // Host -> device: the whole point set (its size may have changed).
      void upload_points(const HostPoints<dim, double> &points);
      // Device -> host: every point array (points that left the grid have material < 0),
      // in the order of the last upload, whatever order the device keeps them in. The
      // last step's pressure averaging, which the engine leaves to the next step's P2G,
      // is applied first.
      void download_points(HostPoints<dim, double> &points) const;
      // The same without waiting (output while the steps go on): the download is queued on
      // the engine's stream into pinned host memory, and steps queued afterwards follow it
      // there; `points` is sized now. The returned function waits for the copy and fills
      // `points` from it; call it once, from any thread, before reading them and before the
      // next begin_download_points (which throws std::logic_error otherwise). The pinned
      // memory (as many bytes as the points hold on the device) is kept for later downloads.
      std::function<void()> begin_download_points(HostPoints<dim, double> &points);
      // The device re-sorts its points by stencil every `steps` steps (0: never), so
      // that the nodal sums of a warp are reduced before the atomics; default 20.
      void set_sort_interval(int steps);
      // Device -> host: nodal mass and velocity (what the output writes) into the host
      // grid's arrays: the same lattice and number of nodes as at construction, numbered
      // as host_grid.lattice_to_node says (which may differ from the construction's where
      // the host's nodes are the whole lattice: one rank starts from lattice_grid and
      // writes into deal.II's DoF numbering).
      void download_nodal(const GridView<dim, double> &host_grid) const;

      // One step on the device; only the reduction (max speed, power of gravity) comes back.
      // The affine transfers (settings.affine_state_variable: the uploaded points hold the
      // matrices), GIMP's domains by U and a material with Hencky's law or Mohr-Coulomb run the
      // step's second variant of kernels (DevicePhysics::all, step.h); everything else the
      // standard one.
      StepReduction<double> step(const StepSettings<dim, double> &settings, double dt);

      // A step queued behind the last one without waiting for it: its time step is computed
      // on the device by rule (time_step_rule.h) from the largest speed of the step queued
      // just before (which must be the one uncollected step) or, with speed_from_host, from
      // host_speed (any other time: the first step, after a collect, a step() or a load).
      // time and next_output are the step's start and the next output time. At most two
      // queued steps may be uncollected, and step() needs none; collect every queued step
      // before reading or changing the points. Misuse throws std::logic_error. Steps whose
      // launches repeat the step before's are replayed as CUDA graphs (MPM_CUDA_GRAPHS=0: not).
      void queue_step(const StepSettings<dim, double> &settings, const TimeStepRule &rule, double time,
                      double next_output, bool speed_from_host, double host_speed);
      // The oldest uncollected queued step's reductions and time step (waits for its end).
      QueuedStep collect_step();
      long       queued_steps() const; // queued and not yet collected
      // Queued steps replayed as a CUDA graph of an earlier one, and graphs captured.
      long graph_replays() const;
      long graph_captures() const;
      PointTotals<dim, double> totals();
      void set_materials(const std::vector<MaterialParameters<double>> &materials);

      // Several ranks: the lattice cell each point was sorted into when it was uploaded
      // (in upload order), and the largest distance of a point outside it, in cell units
      // (core/migration.h), reduced on the device.
      void   set_home_cells(const std::vector<long> &home_cells);
      double max_distance_outside_home_cells();

      // Several ranks: values that travel with each point but that the step does not use
      // (the host's ids and initial positions), arrays of n_points() entries in upload
      // order. They stay on the device, so that a re-sort moves them there too; upload
      // them after each upload_points.
      void upload_labels(const std::vector<std::vector<double>> &labels);
      void download_labels(std::vector<std::vector<double>> &labels) const;

      // Several ranks: the MPI re-sort on the device, where only the points that change
      // rank cross the bus. set_owned_cells: 1 for each lattice cell this rank owns (once
      // per partition). take_leaving_points applies a pending pressure averaging, then
      // splits the points by their current cell: those in other ranks' cells come down
      // into `leaving` with their labels, those that left the grid are dropped (the count
      // is returned), the others stay in their current order with their labels.
      // append_points adds the points received from other ranks, with their labels, at the
      // end. After it, the device's order is the new upload order and every point's home
      // cell is its current cell.
      void set_owned_cells(const std::vector<std::uint8_t> &owned);
      int  take_leaving_points(HostPoints<dim, double> &leaving, std::vector<std::vector<double>> &leaving_labels);
      void append_points(const HostPoints<dim, double> &points, const std::vector<std::vector<double>> &labels);

      int n_points() const;

      // One rank, Grid/Nodes = near material (core/active_nodes.h): the device keeps only the
      // nodes of blocks of block_cells^dim cells near its points as they are now: the box
      // around those blocks, numbered with no lookup, where it is compact enough
      // (box_of_kept_blocks), else the nodes of those blocks found through a block table
      // (NodeBlockChooser). Their masks come from the lattice's faces, the pressure
      // averaging's cell sums sit at each cell's lowest node. Every point's home cell becomes
      // its current cell. A pending averaging is applied first. Returns the number of nodes
      // kept.
      int keep_nodes_near_points(int block_cells, const FaceConditions<dim> &faces);
      // Whether the nodes kept last are a box with no lookup.
      bool kept_nodes_are_box() const;
      // The nodes kept that way: nodal mass and velocity into `nodes` (and its geometry) and
      // the lattice index of each node (-1: beyond the lattice); returns the host view of them
      // in the device's numbering (its block table, if any, the engine's: valid until the
      // next choice).
      GridView<dim, double> download_kept_nodes(HostGrid<dim, double> &nodes, std::vector<long> &lattice_of_node) const;

      // Several ranks: the device time of the ghost exchanges so far, from the end of the
      // work before each to its sums unpacked (the host round trip and MPI included).
      double exchange_seconds();
      // Several ranks: the passes before each exchange run first over the points that can add
      // into an exchanged entry, and the others' pass runs while the sums travel (on by default;
      // MPM_CUDA_OVERLAP=0 turns it off). The mean share of the rank's points that went first,
      // over the sorts so far (-1: never split).
      double share_of_points_before_overlap() const;

    private:
      struct Impl;
      std::unique_ptr<Impl> impl;
      int                   sort_interval = 20;

      // One step with settings in the device's precision (their time_step_on_device, if set,
      // instead of dt); the reduction as the backend returned it.
      StepReduction<Real> run_step(const StepSettings<dim, Real> &settings, Real dt);
      // A queued step's launches: run_step's, or a CUDA graph of an earlier step's.
      void run_queued_step(const StepSettings<dim, Real> &settings);
    };
  } // namespace cuda
} // namespace mpm
