// The background grid as deal.II sees it: a triangulation of a uniform Cartesian box
// (p4est on several ranks, a serial one on one rank) whose cells are k x k (x k) MPM cells
// (Grid/Cells per deal.II cell, k = 1 by default), a Q_k DoFHandler with equidistant
// support points, so that its DoFs are exactly the MPM nodes, nodal fields as distributed
// vectors over the locally relevant nodes, and the lattice lookup and boundary masks that
// the core's GridView reads. "Lattice cell" below is an MPM cell.
//
// In parallel, each rank's node arrays hold its locally relevant nodes: the vertices
// of the lattice cells in its locally owned deal.II cells and of the one layer of lattice
// cells around them, corners included (for k = 1 p4est's ghost layer; for k > 1 the part of
// it next to the owned cells). A point whose centre lies in an owned lattice cell, or less
// than half a cell outside one, has its whole GIMP (and linear) stencil in this set; the
// step loop keeps every point within that distance (doc/performance.md, MPI).
//
// Several ranks with Grid/Nodes = near material (CPU): the cells are of that size only near
// the material and as coarse as the coarse grid elsewhere (coarse_away_from_material); the
// node arrays, lookups and masks above cover the fine cells, whose ghost layer is fine too.
#pragma once

#include <mpm/core/host_storage.h>
#include <mpm/core/views.h>
#include <mpm/dealii/interleaved_exchange.h>
#include <mpm/dealii/parameters.h>

#include <deal.II/base/partitioner.h>
#include <deal.II/distributed/tria.h>
#include <deal.II/dofs/dof_handler.h>
#include <deal.II/fe/fe_q.h>
#include <deal.II/fe/mapping_cartesian.h>
#include <deal.II/lac/la_parallel_vector.h>

#include <array>
#include <memory>
#include <vector>

namespace mpm
{
  // Local node index of the lattice nodes of a box of the lattice (the box around a rank's
  // nodes, so that the lookup takes memory for the rank's cells, not for the lattice): the
  // lookup of GridView (views.h), -1 where the rank holds no node.
  template <int dim>
  struct LatticeNodeMap
  {
    int              lower[dim] = {}; // the box's first lattice node
    int              nodes[dim] = {}; // its nodes along each axis
    std::vector<int> local;           // by the box's index, x fastest
    // The node at lattice node coordinates idx (-1: outside the box or absent).
    int operator()(const int idx[dim]) const
    {
      long index = 0;
      for (int d = dim - 1; d >= 0; --d)
        {
          const int i = idx[d] - lower[d];
          if (i < 0 || i >= nodes[d])
            return -1;
          index = index * nodes[d] + i;
        }
      return local[index];
    }
  };

  // The lattice of the background grid from the prm alone: origin, cell size and cells
  // per direction, no nodal arrays (point generation needs no more, before the grid exists).
  template <int dim>
  HostGrid<dim, double> lattice_geometry(const Parameters &parameters);

  // The nodes of that lattice as an engine on one rank keeps them: every lattice node,
  // numbered in lattice order (x fastest), nodal arrays zero, and the boundary masks of
  // Boundary/* as BackgroundGrid sets them from the faces' boundary ids. It needs no
  // deal.II grid, so one-rank runs start stepping while deal.II builds it. Without
  // nodal_arrays only the geometry and the masks (an engine that keeps only the nodes near
  // the material fills its own).
  template <int dim>
  HostGrid<dim, double> lattice_grid(const Parameters &parameters, bool nodal_arrays = true);

  // Work of a cell for p4est's weighted partition (deal.II's 'weight' signal, no base
  // weight): an empty cell costs 1 unit (node updates), each point Parallel/Point weight
  // units. Integer weights: scaled by 16 so that fractional point weights keep their
  // meaning. p4est reads each cell's weight as an int: capped there (a Point weight of 1e9
  // wrapped around to a negative weight, and p4est's partition aborted).
  // A deal.II cell of n_lattice_cells lattice cells costs that many units. Without
  // empty_cells_cost a cell without points costs nothing (empty_cells_cost()).
  unsigned int cell_partition_weight(double n_points, double point_weight, unsigned int n_lattice_cells = 1,
                                     bool empty_cells_cost = true);

  // Whether the partition's work model counts the cells without points: not where the CPU
  // step visits only the nodes near the material (Grid/Nodes = near material), whose empty
  // box costs no step time; a partition by cells would leave the material to few ranks.
  bool empty_cells_cost(const Parameters &parameters);

  // Several ranks, nodes near the material: the blocks (of Active block size^dim cells) that
  // hold a point on any rank of communicator, ascending, the same on every rank (collective):
  // each rank's own (in any order, repeats allowed) gathered from every rank and merged, so
  // that the messages and the work follow the material, not the box.
  std::vector<long> blocks_of_every_rank(std::vector<long> own, MPI_Comm communicator);

  template <int dim>
  class BackgroundGrid
  {
  public:
    using Vector = dealii::LinearAlgebra::distributed::Vector<double>;

    // start_points (several ranks; every rank gives all of them): the points the run starts
    // with. The grid is then partitioned by their work as p4est refines it (the weights of
    // MaterialPoints' repartition), so that they need not move in a repartition after they
    // are inserted: the same partition, without building the DoFs twice.
    BackgroundGrid(const Parameters &parameters, MPI_Comm communicator,
                   const std::vector<const HostPoints<dim, double> *> &start_points = {});

    // (Re)builds everything that depends on the partition: DoFs, the partitioner,
    // the nodal vectors, the lattice lookups and the boundary masks. Called by the
    // constructor and after every repartition of the triangulation.
    void distribute_nodes();

    // Several ranks with Grid/Nodes = near material (CPU): deal.II's cells are of the full
    // resolution (k lattice cells) only near the material and as coarse as the coarse grid
    // elsewhere. The fine region is a set of blocks of Active block size cells, the same on
    // every rank: the blocks within two blocks of one that holds a point (the nodes kept near
    // the material lie within one). The nodal arrays and lattice lookups cover the fine cells.
    bool coarse_away_from_material() const { return fine_block_cells > 0; }
    // Whether the fine region misses a block within one block of those in holding (blocks
    // that hold a point, the same on every rank); if so it is grown to every block within
    // two, and flag_cells_to_refine() then marks the cells to refine.
    bool fine_region_misses(const std::vector<long> &holding);
    // Sets the refine flag of every owned cell coarser than the full resolution that meets
    // the fine region; whether any rank flagged one (collective).
    bool flag_cells_to_refine();
    // The cell block (of Active block size cells) of a point.
    long block_of(const double *x) const;
    // Number of times the fine region grew after the grid was built.
    int n_refinements = 0;
    // The level of deal.II's cells of the full resolution (the coarse grid's is 0).
    int finest_level = 0;
    // Whether `cell` is of the full resolution (k lattice cells).
    template <typename CellIterator>
    bool is_fine(const CellIterator &cell) const
    {
      return cell->level() == finest_level;
    }

    // Active cell of the triangulation at lattice cell index i + n_x (j + n_y k) (at any
    // level: a coarse cell away from the material holds many), or triangulation.end() where
    // this rank does not own that cell.
    typename dealii::Triangulation<dim>::active_cell_iterator owned_cell(long lattice_cell) const;

    // Lattice cell index of the cell containing x (clamped to the grid).
    long lattice_cell_of(const double *x) const;

    // The lattice cell containing x among those of deal.II cell `cell` (x clamped to it): a
    // point's home cell after the ParticleHandler sorted it into `cell`.
    long lattice_cell_in(const typename dealii::Triangulation<dim>::cell_iterator &cell, const double *x) const;

    // Calls f(lattice cell index) for each of the k^dim lattice cells of deal.II cell `cell`.
    template <typename F>
    void for_each_lattice_cell(const typename dealii::Triangulation<dim>::cell_iterator &cell, F f) const
    {
      long first[dim];
      lower_lattice_corner(cell, first);
      const int k = cells_per_grid_cell;
      for (int s = 0; s < lattice_cells_per_grid_cell; ++s)
        {
          long index = 0;
          for (int d = dim - 1; d >= 0; --d)
            index = index * n_cells[d] + first[d] + (d == 0 ? s % k : d == 1 ? s / k % k : s / (k * k));
          f(index);
        }
    }

    mpm::GridView<dim, double> view();

    // Sums ghost-node contributions to their owners and sends the sums back, on raw
    // arrays laid out as the partitioner's local storage (owned nodes, then ghosts),
    // through the Partitioner's import/export functions. Called by the step after
    // each P2G pass; the arrays may later be device buffers (doc/performance.md, MPI).
    struct Exchange
    {
      const BackgroundGrid *grid;
      template <typename Real>
      void sum_nodal(Real *const *arrays, const int count) const
      {
        grid->sum_nodal(arrays, count);
      }
      // Per-cell sums (pressure averaging) on arrays over lattice cells.
      template <typename Real>
      void sum_cells(Real *const *arrays, const int count) const
      {
        grid->sum_cells(arrays, count);
      }
    };
    Exchange exchange() const { return Exchange{this}; }

    // Bytes one rank sends per array in one sum_nodal (import + export of its ghosts) of
    // values of value_bytes each.
    std::size_t exchange_bytes_per_array(std::size_t value_bytes = sizeof(double)) const;

    // For an engine whose arrays live elsewhere (the GPU) and come to the host only for the
    // exchange. Nodes: the local indices that sum_nodal reads or writes (the owned nodes that
    // other ranks hold as ghosts, ascending, then every ghost node). Cells: the same in the
    // cell partitioner's local numbering, and the lattice cell of each local cell.
    std::vector<unsigned int> exchanged_local_nodes() const;
    std::vector<unsigned int> exchanged_local_cells() const;
    long lattice_cell_of_local_cell(unsigned int local_cell) const { return lattice_cell_of_local_cell_index[local_cell]; }
    // sum_cells on arrays laid out as the cell partitioner's local storage (owned, then ghosts).
    template <typename Real>
    void sum_local_cells(Real *const *arrays, int count) const;
    // The sums on those entries only, packed entry by entry: values[j * count + k] is array
    // k at exchanged_local_nodes()[j] (exchanged_local_cells()[j]); InterleavedExchange::sum_packed.
    template <typename Real>
    void sum_packed_nodes(Real *values, int count) const;
    template <typename Real>
    void sum_packed_cells(Real *values, int count) const;

    MPI_Comm                                  communicator;
    unsigned int                              n_ranks;
    // p4est on several ranks. On one rank a serial Triangulation: the same cells in the same
    // order and the same node numbering, without p4est's 2:1 balance and copy of the forest
    // at each refinement (1.4 s of the 3D granular collapse set-up, 230,400 cells).
    std::unique_ptr<dealii::Triangulation<dim>>        triangulation_storage;
    dealii::Triangulation<dim>                        &triangulation;
    dealii::parallel::distributed::Triangulation<dim> *distributed; // null on one rank
    // Edge of a deal.II cell in lattice cells (k), and k^dim.
    int                                       cells_per_grid_cell;
    int                                       lattice_cells_per_grid_cell;
    dealii::FE_Q<dim>                         fe; // Q_k, support points at the lattice nodes
    dealii::DoFHandler<dim>                   dof_handler;
    // The cells are axis-parallel cubes: real <-> unit coordinates are a shift and a
    // scaling, not MappingQ1's Newton iteration (point generation and every re-sort of
    // the ParticleHandler map each point).
    dealii::MappingCartesian<dim>             mapping;
    dealii::IndexSet                          locally_owned_dofs, locally_relevant_dofs;
    std::shared_ptr<const dealii::Utilities::MPI::Partitioner> partitioner;

    double origin[dim];
    double h;
    int    n_cells[dim];

    // Nodal fields; their local storage (owned, then ghosts) is the core's node array.
    Vector mass, momentum[dim], force[dim], velocity[dim];

    // The partitioner of the lattice cells, numbered (global active cell index) x k^dim +
    // (the lattice cell's place in its deal.II cell, x fastest): the locally owned ones,
    // then the ghost ones (the one layer around them, corners included). For k = 1 the
    // triangulation's partitioner of global active cell indices.
    std::shared_ptr<const dealii::Utilities::MPI::Partitioner> cell_partitioner;

    // Local node index of each lattice node around this rank's (-1 where it holds none).
    // Replaced, not changed, when the nodes are distributed again: an output being written
    // keeps its own.
    std::shared_ptr<const LatticeNodeMap<dim>> lattice_node_map() const { return lattice_to_node; }

  private:
    template <typename Real>
    void sum_nodal(Real *const *arrays, int count) const;

    // Sums per-cell values over ranks, as sum_nodal does for nodes, over the cell
    // partitioner: arrays are indexed by lattice cell; the owned and ghost cells' entries
    // are summed over the ranks that hold them (each rank's own points near a partition
    // boundary add into ghost cells), every other entry is left as it is.
    template <typename Real>
    void sum_cells(Real *const *arrays, int count) const;

    // Lattice cell index of each owned and ghost cell, in the cell partitioner's local order.
    std::vector<long> lattice_cell_of_local_cell_index;

    // Lattice index (along each direction) of the lower corner of deal.II cell `cell`.
    void lower_lattice_corner(const typename dealii::Triangulation<dim>::cell_iterator &cell, long first[dim]) const;

    std::array<BoundaryType, 6> boundary;
    std::shared_ptr<LatticeNodeMap<dim>> lattice_to_node;
    std::vector<std::uint8_t> fixed_components;
    std::vector<std::uint8_t> friction_faces;            // empty without a friction face
    double                    friction_coefficient[6] = {}; // by boundary id
    // The coarse grid's cells by their place along each axis, x fastest, and their edge in
    // lattice cells: owned_cell descends from them (no table per lattice cell).
    std::vector<typename dealii::Triangulation<dim>::cell_iterator> coarse_cells;
    int                                                             coarse_cell_edge = 0;
    int                                                             coarse_cells_along[dim] = {};

    // Coarse away from the material: the block edge (0: the grid is uniform) and the fine
    // region, one byte per cell block.
    int                        fine_block_cells = 0;
    std::vector<unsigned char> fine_blocks;
    // Calls f(lattice cell) for the lattice cells of the box of count[d] cells from lattice
    // cell first[d] along each axis.
    template <typename F>
    void for_each_lattice_cell_in_box(const long first[dim], const long count[dim], F &&f) const;
    // The box of blocks (along each axis, inclusive) around the fine region: a coarse cell far
    // from the material is not searched block by block.
    long fine_region_lower[dim] = {}, fine_region_upper[dim] = {};
    // Whether `cell` covers a lattice cell of a block of the fine region.
    bool meets_fine_region(const typename dealii::Triangulation<dim>::cell_iterator &cell) const;

    // The exchanges over the node and the cell partitioner (all arrays of a call in one
    // round of messages), and the scratch of sum_cells.
    mutable InterleavedExchange node_exchange, cell_exchange;
    mutable std::vector<double> cell_buffer_double;
    mutable std::vector<float>  cell_buffer_float;
  };
} // namespace mpm
