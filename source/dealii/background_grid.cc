#include <mpm/dealii/background_grid.h>
#include <mpm/core/active_nodes.h>

#include <deal.II/base/partitioner.templates.h>
#include <deal.II/base/quadrature_lib.h>
#include <deal.II/base/utilities.h>
#include <deal.II/dofs/dof_tools.h>
#include <deal.II/grid/grid_generator.h>

#include <algorithm>
#include <cmath>
#include <limits>

namespace mpm
{
  namespace
  {
    bool has_friction_face(const std::array<BoundaryType, 6> &boundary)
    {
      return std::find(boundary.begin(), boundary.end(), BoundaryType::friction) != boundary.end();
    }

    // Parameters::cells_per_grid_cell, refused (before FE_Q is built from it) outside the prm's 1..16:
    // a library user may fill Parameters without the prm.
    int checked_cells_per_grid_cell(const int k)
    {
      AssertThrow(k >= 1 && k <= 16, dealii::ExcMessage("Grid/Cells per deal.II cell (Parameters::cells_per_grid_cell) "
                                                        "must be an integer from 1 to 16, got " + std::to_string(k) +
                                                        "."));
      return k;
    }

    // mu of boundary id `id` (0 unless the face is friction).
    double face_friction_coefficient(const Parameters &parameters, const unsigned int id)
    {
      return parameters.boundary[id] == BoundaryType::friction ? parameters.friction_coefficient : 0.0;
    }

    // A box of lattice entries (cells or nodes, `extent` of them along each axis) and an
    // entry's index in it, x fastest: arrays over the box around what a rank holds, not over
    // the lattice, whose box may be mostly empty (Grid/Nodes = near material).
    template <int dim>
    struct LatticeBox
    {
      long lower[dim], upper[dim]; // inclusive; empty while lower > upper

      LatticeBox()
      {
        std::fill(lower, lower + dim, std::numeric_limits<long>::max());
        std::fill(upper, upper + dim, -1L);
      }
      static void coordinates(long entry, const long extent[dim], long idx[dim])
      {
        for (int d = 0; d < dim; ++d)
          {
            idx[d] = entry % extent[d];
            entry /= extent[d];
          }
      }
      void add_at(const long idx[dim])
      {
        for (int d = 0; d < dim; ++d)
          {
            lower[d] = std::min(lower[d], idx[d]);
            upper[d] = std::max(upper[d], idx[d]);
          }
      }
      void add(const long entry, const long extent[dim])
      {
        long idx[dim];
        coordinates(entry, extent, idx);
        add_at(idx);
      }
      // Grown by `by` entries on every side, within the lattice.
      void grow(const long by, const long extent[dim])
      {
        for (int d = 0; d < dim; ++d)
          if (lower[d] <= upper[d])
            {
              lower[d] = std::max(0L, lower[d] - by);
              upper[d] = std::min(extent[d] - 1, upper[d] + by);
            }
      }
      long along(const int d) const { return std::max(0L, upper[d] - lower[d] + 1); }
      long size() const
      {
        long n = 1;
        for (int d = 0; d < dim; ++d)
          n *= along(d);
        return n;
      }
      long index_at(const long idx[dim]) const
      {
        long index = 0;
        for (int d = dim - 1; d >= 0; --d)
          {
            if (idx[d] < lower[d] || idx[d] > upper[d])
              return -1;
            index = index * along(d) + idx[d] - lower[d];
          }
        return index;
      }
      // -1 outside the box.
      long index(const long entry, const long extent[dim]) const
      {
        long idx[dim];
        coordinates(entry, extent, idx);
        return index_at(idx);
      }
      // The part of the box of count[d] entries from first[d] inside this box; false if none.
      bool clip(long first[dim], long count[dim]) const
      {
        for (int d = 0; d < dim; ++d)
          {
            const long from = std::max(first[d], lower[d]), to = std::min(first[d] + count[d] - 1, upper[d]);
            if (from > to)
              return false;
            first[d] = from;
            count[d] = to - from + 1;
          }
        return true;
      }
    };

    template <int dim>
    void cell_extent(const int n_cells[dim], long extent[dim])
    {
      for (int d = 0; d < dim; ++d)
        extent[d] = n_cells[d];
    }
  } // namespace

  template <int dim>
  HostGrid<dim, double> lattice_geometry(const Parameters &parameters)
  {
    HostGrid<dim, double> lattice;
    lattice.h = parameters.cell_size;
    for (unsigned int d = 0; d < dim; ++d)
      {
        lattice.origin[d]  = parameters.lower[d];
        lattice.n_cells[d] = static_cast<int>(std::lround((parameters.upper[d] - parameters.lower[d]) / lattice.h));
      }
    return lattice;
  }

  template <int dim>
  HostGrid<dim, double> lattice_grid(const Parameters &parameters, const bool nodal_arrays)
  {
    const HostGrid<dim, double> lattice = lattice_geometry<dim>(parameters);
    HostGrid<dim, double>       grid;
    if (nodal_arrays)
      grid.make_dense(lattice.origin, lattice.h, lattice.n_cells);
    else
      grid = lattice;
    // A node on face id (x min, x max, y min, ...) takes that face's mask: no-slip fixes
    // every component, free-slip the normal one, friction sets bit id of its friction
    // mask; edges and corners combine their faces'.
    for (unsigned int id = 0; id < 2 * dim; ++id)
      {
        const BoundaryType type       = parameters.boundary[id];
        grid.faces.fixed[id]          = type == BoundaryType::no_slip   ? std::uint8_t((1u << dim) - 1) :
                                        type == BoundaryType::free_slip ? std::uint8_t(1u << (id / 2)) :
                                                                          std::uint8_t(0);
        grid.faces.friction[id]       = type == BoundaryType::friction;
        grid.friction_coefficient[id] = face_friction_coefficient(parameters, id);
      }
    if (!nodal_arrays) // the engine computes the masks of the nodes it keeps
      return grid;
    const long n_nodes = static_cast<long>(grid.mass.size());
    if (grid.faces.any_friction())
      grid.friction_faces.assign(n_nodes, 0);
    for (long l = 0; l < n_nodes; ++l)
      {
        int          idx[dim];
        std::uint8_t friction = 0;
        grid.lattice_coordinates(l, idx);
        node_boundary_masks<dim>(grid.faces, grid.n_cells, idx, grid.fixed_components[l], friction);
        if (friction != 0)
          grid.friction_faces[l] = friction;
      }
    return grid;
  }

  unsigned int cell_partition_weight(const double n_points, const double point_weight,
                                     const unsigned int n_lattice_cells, const bool empty_cells_cost)
  {
    constexpr double max_weight = std::numeric_limits<int>::max();
    const double     per_point  = std::min(std::round(16 * point_weight), max_weight);
    const double     per_cells  = empty_cells_cost || n_points > 0 ? 16.0 * n_lattice_cells : 0.0;
    return static_cast<unsigned int>(std::min(per_cells + per_point * n_points, max_weight));
  }

  bool empty_cells_cost(const Parameters &parameters)
  {
    return !(parameters.active_block_cells > 0 && parameters.backend.name == "cpu");
  }

  std::vector<long> blocks_of_every_rank(std::vector<long> own, MPI_Comm communicator)
  {
    std::sort(own.begin(), own.end());
    own.erase(std::unique(own.begin(), own.end()), own.end());
    std::vector<long> all;
    for (const std::vector<long> &of_rank : dealii::Utilities::MPI::all_gather(communicator, own))
      all.insert(all.end(), of_rank.begin(), of_rank.end());
    std::sort(all.begin(), all.end());
    all.erase(std::unique(all.begin(), all.end()), all.end());
    return all;
  }

  template <int dim>
  BackgroundGrid<dim>::BackgroundGrid(const Parameters &parameters, MPI_Comm communicator,
                                      const std::vector<const HostPoints<dim, double> *> &start_points)
    : communicator(communicator)
    , n_ranks(dealii::Utilities::MPI::n_mpi_processes(communicator))
    , triangulation_storage(n_ranks > 1 ? std::make_unique<dealii::parallel::distributed::Triangulation<dim>>(communicator) :
                                          std::make_unique<dealii::Triangulation<dim>>())
    , triangulation(*triangulation_storage)
    , distributed(dynamic_cast<dealii::parallel::distributed::Triangulation<dim> *>(&triangulation))
    , cells_per_grid_cell(checked_cells_per_grid_cell(parameters.cells_per_grid_cell))
    , lattice_cells_per_grid_cell(dealii::Utilities::pow(parameters.cells_per_grid_cell, dim))
    , fe(dealii::QIterated<1>(dealii::QTrapezoid<1>(), cells_per_grid_cell))
    , dof_handler(triangulation)
    , boundary(parameters.boundary)
  {
    for (unsigned int id = 0; id < 2 * dim; ++id)
      friction_coefficient[id] = face_friction_coefficient(parameters, id);
    const HostGrid<dim, double> lattice = lattice_geometry<dim>(parameters);
    h = lattice.h;
    std::vector<unsigned int> repetitions(dim);
    dealii::Point<dim>        p1, p2;
    // p4est orders the coarse cells as given (lexicographically: a partition into
    // slabs) and the cells inside each coarse cell along a Morton curve (compact
    // blocks, fewer ghost nodes per owned node). Coarse cells of 2^levels x 2^levels
    // deal.II cells (of k x k lattice cells each), refined globally, give the same lattice
    // with compact partitions.
    const int    k      = cells_per_grid_cell;
    unsigned int levels = 10;
    for (unsigned int d = 0; d < dim; ++d)
      {
        origin[d]  = lattice.origin[d];
        n_cells[d] = lattice.n_cells[d];
        AssertThrow(n_cells[d] % k == 0, dealii::ExcMessage("Grid/Cells per deal.II cell must divide the cells "
                                                            "along every direction."));
        unsigned int twos = 0;
        while (twos < levels && (n_cells[d] / k >> twos) % 2 == 0)
          ++twos;
        levels = std::min(levels, twos);
        p1[d]  = parameters.lower[d];
        p2[d]  = parameters.lower[d] + n_cells[d] * h;
      }
    for (unsigned int d = 0; d < dim; ++d)
      repetitions[d] = n_cells[d] / k >> levels;
    finest_level = levels;
    // Near the material on several ranks (CPU): fine only around the start points (every rank
    // has all of them), grown later as the points spread (MaterialPoints::refine_near_points).
    if (n_ranks > 1 && !empty_cells_cost(parameters))
      {
        fine_block_cells = parameters.active_block_cells;
        fine_blocks.assign(mpm::n_blocks<dim>(n_cells, fine_block_cells), 0);
        std::fill(fine_region_lower, fine_region_lower + dim, std::numeric_limits<long>::max());
        std::fill(fine_region_upper, fine_region_upper + dim, -1L);
        std::vector<long> holding;
        for (const HostPoints<dim, double> *points : start_points)
          for (int i = 0; i < points->size(); ++i)
            {
              double x[dim];
              for (int d = 0; d < dim; ++d)
                x[d] = points->position[d][i];
              if (const long b = block_of(x); holding.empty() || holding.back() != b)
                holding.push_back(b);
            }
        std::sort(holding.begin(), holding.end());
        holding.erase(std::unique(holding.begin(), holding.end()), holding.end());
        fine_region_misses(holding);
      }
    // colorize: boundary ids 0..2dim-1 for x min, x max, y min, ...; children inherit them.
    dealii::GridGenerator::subdivided_hyper_rectangle(triangulation, repetitions, p1, p2, true);
    coarse_cell_edge = k << levels;
    for (unsigned int d = 0; d < dim; ++d)
      coarse_cells_along[d] = static_cast<int>(repetitions[d]);
    coarse_cells.resize(triangulation.n_cells(0));
    for (const auto &cell : triangulation.cell_iterators_on_level(0))
      {
        long first[dim], place = 0;
        lower_lattice_corner(cell, first);
        for (int d = dim - 1; d >= 0; --d)
          place = place * coarse_cells_along[d] + first[d] / coarse_cell_edge;
        coarse_cells[place] = cell;
      }
    // Several ranks: p4est partitions the refined cells by the start points' work (the
    // partition after refine_global; Parallel/Load balance threshold 0 leaves it by cells).
    // Counted per lattice cell of the box around the points in a plain array (a hash map took
    // seconds for P1's 25.7M points), not over the lattice: the box may be mostly empty.
    boost::signals2::scoped_connection weights;
    LatticeBox<dim>                    points_box;
    std::vector<unsigned int>          points_in_cell;
    if (distributed != nullptr && !start_points.empty() && parameters.parallel.load_balance_threshold > 0)
      {
        long cells[dim];
        cell_extent<dim>(n_cells, cells);
        for (const HostPoints<dim, double> *points : start_points)
          for (int i = 0; i < points->size(); ++i)
            {
              double x[dim];
              for (int d = 0; d < dim; ++d)
                x[d] = points->position[d][i];
              points_box.add(lattice_cell_of(x), cells);
            }
        points_in_cell.assign(points_box.size(), 0);
        for (const HostPoints<dim, double> *points : start_points)
          for (int i = 0; i < points->size(); ++i)
            {
              double x[dim];
              for (int d = 0; d < dim; ++d)
                x[d] = points->position[d][i];
              ++points_in_cell[points_box.index(lattice_cell_of(x), cells)];
            }
        const double       point_weight  = parameters.parallel.point_weight;
        const bool         empty_cost    = empty_cells_cost(parameters);
        const unsigned int lattice_cells = lattice_cells_per_grid_cell;
        using CellIterator        = typename dealii::Triangulation<dim>::cell_iterator;
        using CellStatus          = typename dealii::Triangulation<dim>::CellStatus;
        // p4est partitions after each level of refine_global. deal.II asks for the weights of a
        // refined cell's children one after the other, handing over the parent (the children
        // do not exist yet). In deal.II 9.4 the first child comes with CELL_REFINE, the others
        // with CELL_INVALID (taking both as children is what makes test_build_partition find
        // no cell moved). Child k is the parent's k-th corner, bit d of k set for the upper
        // half in direction d. Each gets the mean work of the lattice cells it covers (at the
        // last level its own cells'; before, proportional to their sum without overflowing
        // p4est's int weights). Every child given the lattice cell at the parent's centre, as
        // before, left the build's partition unlike the repartition's (doc/log.md, 2026-12-02).
        weights = triangulation.signals.weight.connect(
          [&points_in_cell, &points_box, point_weight, empty_cost, lattice_cells, this, parent = std::pair<int, int>(-1, -1),
           next_child = 0u](
            const CellIterator &cell, const CellStatus status) mutable -> unsigned int {
            constexpr unsigned int last_vertex = dealii::GeometryInfo<dim>::vertices_per_cell - 1;
            dealii::Point<dim>     lower = cell->vertex(0), upper = cell->vertex(last_vertex);
            if (status == dealii::Triangulation<dim>::CELL_REFINE ||
                status == dealii::Triangulation<dim>::CELL_INVALID)
              {
                if (std::make_pair(cell->level(), cell->index()) != parent)
                  {
                    parent     = {cell->level(), cell->index()};
                    next_child = 0;
                  }
                const unsigned int k = next_child++ % dealii::GeometryInfo<dim>::max_children_per_cell;
                for (int d = 0; d < dim; ++d)
                  {
                    const double middle = 0.5 * (lower[d] + upper[d]);
                    (k >> d & 1 ? lower[d] : upper[d]) = middle;
                  }
              }
            long first[dim], count[dim], n = 1;
            for (int d = 0; d < dim; ++d)
              {
                first[d] = std::lround((lower[d] - origin[d]) / h);
                count[d] = std::max(1L, std::lround((upper[d] - lower[d]) / h));
                n *= count[d];
              }
            double points = 0; // (the lattice cells outside the points' box hold none)
            if (points_box.clip(first, count))
              {
                long cells[dim];
                cell_extent<dim>(n_cells, cells);
                for_each_lattice_cell_in_box(first, count,
                                             [&](const long index) { points += points_in_cell[points_box.index(index, cells)]; });
              }
            // A deal.II cell's weight: k^dim times that mean.
            return cell_partition_weight(points * lattice_cells / n, point_weight, lattice_cells, empty_cost);
          });
      }
    bool refined = false;
    if (coarse_away_from_material())
      for (unsigned int level = 0; level < levels && flag_cells_to_refine(); ++level, refined = true)
        triangulation.execute_coarsening_and_refinement();
    else
      {
        triangulation.refine_global(levels);
        refined = levels > 0;
      }
    if (weights.connected() && !refined) // no refinement, so no partition after it
      distributed->repartition();
    weights.disconnect();
    distribute_nodes();
  }

  template <int dim>
  void BackgroundGrid<dim>::distribute_nodes()
  {
    long lattice_cells[dim];
    cell_extent<dim>(n_cells, lattice_cells);
    const int k  = cells_per_grid_cell;
    const int kd = lattice_cells_per_grid_cell;

    dof_handler.distribute_dofs(fe);
    locally_owned_dofs = dof_handler.locally_owned_dofs();

    // The lattice cells: 1 in an owned fine deal.II cell, 2 in the one layer around those
    // (corners included; for k = 1 p4est's ghost cells), 0 elsewhere; kept over the box of
    // the owned fine cells and that layer.
    LatticeBox<dim> state_box;
    for (const auto &cell : triangulation.active_cell_iterators())
      if (cell->is_locally_owned() && is_fine(cell))
        for_each_lattice_cell(cell, [&](const long c) { state_box.add(c, lattice_cells); });
    state_box.grow(1, lattice_cells);
    std::vector<std::uint8_t> cell_states(state_box.size(), 0);
    auto                      cell_state = [&](const long c) -> std::uint8_t {
      const long in_box = state_box.index(c, lattice_cells);
      return in_box < 0 ? 0 : cell_states[in_box];
    };
    auto set_cell_state = [&](const long c, const std::uint8_t state) {
      const long in_box = state_box.index(c, lattice_cells);
      AssertThrow(in_box >= 0, dealii::ExcInternalError()); // the box holds the owned cells and their layer
      cell_states[in_box] = state;
    };
    for (const auto &cell : triangulation.active_cell_iterators())
      if (cell->is_locally_owned() && is_fine(cell))
        for_each_lattice_cell(cell, [&](const long c) { set_cell_state(c, 1); });
    auto cell_coordinates = [&](long index, long idx[dim]) { LatticeBox<dim>::coordinates(index, lattice_cells, idx); };
    // Some lattice cell among the 3^dim around cell `idx` (offset -1..1) or the 2^dim around
    // node `idx` (offset -1..0) that is owned (only_owned) or owned or in the layer.
    auto any_around = [&](const long idx[dim], const bool of_node, const bool only_owned) {
      const int lowest = -1, highest = of_node ? 0 : 1, width = highest - lowest + 1;
      for (int j = 0; j < dealii::Utilities::pow(width, dim); ++j)
        {
          long index = 0;
          bool in    = true;
          for (int d = dim - 1, rest = j; d >= 0; --d)
            {
              const int  step = dealii::Utilities::pow(width, d);
              const long i    = idx[d] + lowest + rest / step;
              rest %= step;
              in    = in && i >= 0 && i < n_cells[d];
              index = index * n_cells[d] + (in ? i : 0);
            }
          if (in && (only_owned ? cell_state(index) == 1 : cell_state(index) != 0))
            return true;
        }
      return false;
    };
    for (const auto &cell : triangulation.active_cell_iterators())
      if (cell->is_ghost() && is_fine(cell))
        for_each_lattice_cell(cell, [&](const long c) {
          long idx[dim];
          cell_coordinates(c, idx);
          if (any_around(idx, false, true)) // not the cells of the layer marked so far
            set_cell_state(c, 2);
        });

    // The locally relevant nodes: every DoF of an owned cell, and those of the ghost cells
    // that are a vertex of a lattice cell in the layer (for k = 1 all of them: deal.II's
    // locally relevant DoFs). A DoF's lattice node is its support point's.
    const std::vector<dealii::Point<dim>>        &unit = fe.get_unit_support_points();
    std::vector<dealii::types::global_dof_index> dofs(fe.n_dofs_per_cell());
    // Calls f(DoF, lattice node coordinates) for each relevant DoF of non-artificial cell `cell`.
    auto for_each_relevant_dof = [&](const auto &cell, const auto &f) {
      cell->get_dof_indices(dofs);
      long first[dim];
      lower_lattice_corner(cell, first);
      for (unsigned int i = 0; i < dofs.size(); ++i)
        {
          long idx[dim];
          for (int d = 0; d < dim; ++d)
            idx[d] = first[d] + std::lround(unit[i][d] * k);
          if (k == 1 || cell->is_locally_owned() || any_around(idx, true, false))
            f(dofs[i], idx);
        }
    };
    if (k == 1)
      dealii::DoFTools::extract_locally_relevant_dofs(dof_handler, locally_relevant_dofs);
    else
      {
        dealii::DoFTools::extract_locally_active_dofs(dof_handler, locally_relevant_dofs); // the owned cells'
        std::vector<dealii::types::global_dof_index> layer;
        for (const auto &cell : dof_handler.active_cell_iterators())
          if (cell->is_ghost() && is_fine(cell))
            for_each_relevant_dof(cell, [&](const auto dof, const long *) { layer.push_back(dof); });
        std::sort(layer.begin(), layer.end());
        layer.erase(std::unique(layer.begin(), layer.end()), layer.end());
        locally_relevant_dofs.add_indices(layer.begin(), layer.end());
      }
    partitioner = std::make_shared<dealii::Utilities::MPI::Partitioner>(locally_owned_dofs, locally_relevant_dofs,
                                                                       communicator);
    mass.reinit(partitioner);
    for (unsigned int d = 0; d < dim; ++d)
      {
        momentum[d].reinit(partitioner);
        force[d].reinit(partitioner);
        velocity[d].reinit(partitioner);
      }

    const unsigned int n_local_nodes = partitioner->locally_owned_size() + partitioner->n_ghost_indices();
    // The lookup over the box of the rank's nodes (a coarse cell's DoFs are no lattice nodes).
    LatticeBox<dim> node_box;
    for (const auto &cell : dof_handler.active_cell_iterators())
      if (!cell->is_artificial() && is_fine(cell))
        for_each_relevant_dof(cell, [&](const auto, const long *idx) { node_box.add_at(idx); });
    auto node_map = std::make_shared<LatticeNodeMap<dim>>();
    for (unsigned int d = 0; d < dim; ++d)
      {
        node_map->lower[d] = node_box.along(d) > 0 ? static_cast<int>(node_box.lower[d]) : 0;
        node_map->nodes[d] = static_cast<int>(node_box.along(d));
      }
    node_map->local.assign(node_box.size(), -1);
    for (const auto &cell : dof_handler.active_cell_iterators())
      if (!cell->is_artificial() && is_fine(cell))
        for_each_relevant_dof(cell, [&](const auto dof, const long *idx) {
          node_map->local[node_box.index_at(idx)] = static_cast<int>(partitioner->global_to_local(dof));
        });
    lattice_to_node = node_map;
    fixed_components.assign(n_local_nodes, 0);
    friction_faces.assign(has_friction_face(boundary) ? n_local_nodes : 0, 0);

    // Boundary masks from the face ids: no-slip fixes every component, free-slip the normal
    // one, friction marks the face in the node's friction mask. Every cell holding a boundary
    // node has a face with that node on that boundary, so ghost nodes get the same masks as
    // on their owner.
    std::vector<dealii::types::global_dof_index> face_dofs(fe.n_dofs_per_face());
    for (const auto &cell : dof_handler.active_cell_iterators())
      {
        if (cell->is_artificial())
          continue;
        for (const unsigned int f : cell->face_indices())
          if (cell->face(f)->at_boundary())
            {
              const unsigned int id   = cell->face(f)->boundary_id();
              const BoundaryType type = boundary[id];
              if (type == BoundaryType::free)
                continue;
              const std::uint8_t bits = type == BoundaryType::no_slip ? std::uint8_t((1u << dim) - 1) :
                                        type == BoundaryType::free_slip ? std::uint8_t(1u << (id / 2)) :
                                                                          std::uint8_t(0);
              cell->face(f)->get_dof_indices(face_dofs);
              for (const auto dof : face_dofs)
                if (locally_relevant_dofs.is_element(dof))
                  {
                    const auto node = partitioner->global_to_local(dof);
                    fixed_components[node] |= bits;
                    if (type == BoundaryType::friction)
                      friction_faces[node] |= std::uint8_t(1u << id);
                  }
            }
      }

    // The partitioner of the lattice cells for the per-cell sums of the pressure averaging:
    // lattice cell s of deal.II cell c is (global active cell index of c) x k^dim + s. The
    // owned deal.II cells' global indices are one range on each rank, so are their lattice
    // cells'.
    dealii::types::global_cell_index first_owned = std::numeric_limits<dealii::types::global_cell_index>::max(),
                                     n_owned     = 0;
    std::vector<dealii::types::global_cell_index> ghost_cells;
    for (const auto &cell : triangulation.active_cell_iterators())
      if (cell->is_locally_owned())
        {
          first_owned = std::min(first_owned, cell->global_active_cell_index());
          ++n_owned;
        }
      else if (cell->is_ghost() && is_fine(cell))
        {
          int s = 0;
          for_each_lattice_cell(cell, [&](const long c) {
            if (cell_state(c) == 2)
              ghost_cells.push_back(cell->global_active_cell_index() * kd + s);
            ++s;
          });
        }
    const dealii::types::global_cell_index n_global_cells =
      dealii::Utilities::MPI::sum<dealii::types::global_cell_index>(n_owned, communicator) * kd;
    dealii::IndexSet owned_cells(n_global_cells), ghost_cell_set(n_global_cells);
    if (n_owned > 0)
      owned_cells.add_range(first_owned * kd, (first_owned + n_owned) * kd);
    std::sort(ghost_cells.begin(), ghost_cells.end());
    ghost_cell_set.add_indices(ghost_cells.begin(), ghost_cells.end());
    auto cells = std::make_shared<dealii::Utilities::MPI::Partitioner>(owned_cells, ghost_cell_set, communicator);
    lattice_cell_of_local_cell_index.assign(cells->locally_owned_size() + cells->n_ghost_indices(), -1);
    for (const auto &cell : triangulation.active_cell_iterators())
      if (cell->is_locally_owned() || (cell->is_ghost() && is_fine(cell)))
        {
          AssertThrow(!cell->is_locally_owned() || cell->global_active_cell_index() - first_owned < n_owned,
                      dealii::ExcInternalError()); // the owned cells' indices are one range
          if (!is_fine(cell)) // a coarse owned cell's entries stay -1: no lattice cell
            continue;
          int s = 0;
          for_each_lattice_cell(cell, [&](const long c) {
            const dealii::types::global_cell_index global = cell->global_active_cell_index() * kd + s++;
            if (cell_state(c) != 0)
              lattice_cell_of_local_cell_index[cells->global_to_local(global)] = c;
          });
        }
    cell_partitioner = cells;
  }

  template <int dim>
  template <typename F>
  void BackgroundGrid<dim>::for_each_lattice_cell_in_box(const long first[dim], const long count[dim], F &&f) const
  {
    long n = 1;
    for (int d = 0; d < dim; ++d)
      n *= count[d];
    for (long j = 0; j < n; ++j)
      {
        long index = 0, rest = j, at[dim];
        for (int d = 0; d < dim; ++d)
          {
            at[d] = first[d] + rest % count[d];
            rest /= count[d];
          }
        for (int d = dim - 1; d >= 0; --d)
          index = index * n_cells[d] + at[d];
        f(index);
      }
  }

  template <int dim>
  bool BackgroundGrid<dim>::meets_fine_region(const typename dealii::Triangulation<dim>::cell_iterator &cell) const
  {
    const int B = fine_block_cells;
    long      first[dim], lo[dim], hi[dim], nb[dim], n = 1;
    lower_lattice_corner(cell, first);
    const dealii::Point<dim> upper = cell->vertex(dealii::GeometryInfo<dim>::vertices_per_cell - 1);
    for (int d = 0; d < dim; ++d)
      {
        lo[d] = std::max(first[d] / B, fine_region_lower[d]);
        hi[d] = std::min((std::lround((upper[d] - origin[d]) / h) - 1) / B, fine_region_upper[d]);
        if (lo[d] > hi[d])
          return false;
        nb[d] = n_blocks_along<dim>(n_cells[d], B);
        n *= hi[d] - lo[d] + 1;
      }
    for (long j = 0; j < n; ++j)
      {
        long block = 0, rest = j, at[dim];
        for (int d = 0; d < dim; ++d)
          {
            at[d] = lo[d] + rest % (hi[d] - lo[d] + 1);
            rest /= hi[d] - lo[d] + 1;
          }
        for (int d = dim - 1; d >= 0; --d)
          block = block * nb[d] + at[d];
        if (fine_blocks[block] != 0)
          return true;
      }
    return false;
  }

  template <int dim>
  long BackgroundGrid<dim>::block_of(const double *x) const
  {
    return block_of_cell<dim>(lattice_cell_of(x), n_cells, fine_block_cells);
  }

  template <int dim>
  bool BackgroundGrid<dim>::fine_region_misses(const std::vector<long> &holding)
  {
    const int B = fine_block_cells;
    long      nb[dim];
    for (int d = 0; d < dim; ++d)
      nb[d] = n_blocks_along<dim>(n_cells[d], B);
    // The blocks within `reach` blocks (max-norm) of one in holding, ascending.
    const auto dilated = [&](const int reach) {
      std::vector<long> out;
      const int         width = 2 * reach + 1;
      for (const long b : holding)
        {
          long at[dim], rest = b;
          for (int d = 0; d < dim; ++d)
            {
              at[d] = rest % nb[d];
              rest /= nb[d];
            }
          for (int j = 0; j < dealii::Utilities::pow(width, dim); ++j)
            {
              long neighbour = 0;
              bool inside    = true;
              for (int d = dim - 1, r = j; d >= 0; --d)
                {
                  const int  step = dealii::Utilities::pow(width, d);
                  const long i    = at[d] - reach + r / step;
                  r %= step;
                  inside    = inside && i >= 0 && i < nb[d];
                  neighbour = neighbour * nb[d] + (inside ? i : 0);
                }
              if (inside)
                out.push_back(neighbour);
            }
        }
      std::sort(out.begin(), out.end());
      out.erase(std::unique(out.begin(), out.end()), out.end());
      return out;
    };
    const std::vector<long> kept = dilated(1);
    const bool miss = std::any_of(kept.begin(), kept.end(), [&](const long b) { return fine_blocks[b] == 0; });
    if (miss)
      for (const long b : dilated(2))
        {
          fine_blocks[b] = 1;
          long rest      = b;
          for (int d = 0; d < dim; ++d)
            {
              const long at = rest % nb[d];
              rest /= nb[d];
              fine_region_lower[d] = std::min(fine_region_lower[d], at);
              fine_region_upper[d] = std::max(fine_region_upper[d], at);
            }
        }
    return miss;
  }

  template <int dim>
  bool BackgroundGrid<dim>::flag_cells_to_refine()
  {
    int flagged = 0;
    for (const auto &cell : triangulation.active_cell_iterators())
      if (cell->is_locally_owned() && cell->level() < finest_level && meets_fine_region(cell))
        {
          cell->set_refine_flag();
          flagged = 1;
        }
    return dealii::Utilities::MPI::max(flagged, communicator) > 0;
  }

  template <int dim>
  typename dealii::Triangulation<dim>::active_cell_iterator BackgroundGrid<dim>::owned_cell(const long c) const
  {
    long cells[dim], idx[dim], place = 0;
    cell_extent<dim>(n_cells, cells);
    LatticeBox<dim>::coordinates(c, cells, idx);
    for (int d = dim - 1; d >= 0; --d)
      place = place * coarse_cells_along[d] + idx[d] / coarse_cell_edge;
    // Down from the coarse cell: child j is the corner with bit d of j set for the upper half
    // along d (deal.II's numbering of a hypercube's children).
    typename dealii::Triangulation<dim>::cell_iterator cell = coarse_cells[place];
    long                                               first[dim];
    for (int d = 0; d < dim; ++d)
      first[d] = idx[d] / coarse_cell_edge * coarse_cell_edge;
    for (long edge = coarse_cell_edge; cell->has_children(); edge /= 2)
      {
        unsigned int child = 0;
        for (int d = 0; d < dim; ++d)
          if (idx[d] - first[d] >= edge / 2)
            {
              child |= 1u << d;
              first[d] += edge / 2;
            }
        cell = cell->child(child);
      }
    return cell->is_locally_owned() ? typename dealii::Triangulation<dim>::active_cell_iterator(cell) :
                                      triangulation.end();
  }

  template <int dim>
  long BackgroundGrid<dim>::lattice_cell_of(const double *x) const
  {
    return mpm::lattice_cell_containing<dim>(origin, h, n_cells, x);
  }

  template <int dim>
  void BackgroundGrid<dim>::lower_lattice_corner(const typename dealii::Triangulation<dim>::cell_iterator &cell,
                                                 long first[dim]) const
  {
    const dealii::Point<dim> lower = cell->vertex(0); // the cells are axis-parallel boxes
    for (int d = 0; d < dim; ++d)
      first[d] = std::lround((lower[d] - origin[d]) / h);
  }

  template <int dim>
  long BackgroundGrid<dim>::lattice_cell_in(const typename dealii::Triangulation<dim>::cell_iterator &cell,
                                            const double *x) const
  {
    long first[dim];
    lower_lattice_corner(cell, first);
    long index = 0;
    for (int d = dim - 1; d >= 0; --d)
      {
        const long i = std::clamp(static_cast<long>(std::floor((x[d] - origin[d]) / h)), first[d],
                                  first[d] + cells_per_grid_cell - 1);
        index        = index * n_cells[d] + i;
      }
    return index;
  }

  template <int dim>
  mpm::GridView<dim, double> BackgroundGrid<dim>::view()
  {
    mpm::GridView<dim, double> v{};
    for (unsigned int d = 0; d < dim; ++d)
      {
        v.origin[d]   = origin[d];
        v.n_cells[d]  = n_cells[d];
        v.momentum[d] = momentum[d].begin();
        v.force[d]    = force[d].begin();
        v.velocity[d] = velocity[d].begin();
      }
    v.h                = h;
    v.lattice_to_node  = lattice_to_node->local.data();
    for (unsigned int d = 0; d < dim; ++d)
      {
        v.box_lower[d] = lattice_to_node->lower[d];
        v.box_nodes[d] = lattice_to_node->nodes[d];
      }
    v.n_nodes          = static_cast<int>(fixed_components.size());
    v.mass             = mass.begin();
    v.fixed_components = fixed_components.data();
    if (!friction_faces.empty())
      {
        v.friction_faces = friction_faces.data();
        for (unsigned int id = 0; id < 2 * dim; ++id)
          v.friction_coefficient[id] = friction_coefficient[id];
      }
    return v;
  }

  template <int dim>
  std::size_t BackgroundGrid<dim>::exchange_bytes_per_array(const std::size_t value_bytes) const
  {
    // Import sends each ghost entry to its owner, export sends it back.
    return 2 * value_bytes * partitioner->n_ghost_indices();
  }

  template <int dim>
  std::vector<unsigned int> BackgroundGrid<dim>::exchanged_local_nodes() const
  {
    return InterleavedExchange::packed_indices(*partitioner);
  }

  template <int dim>
  std::vector<unsigned int> BackgroundGrid<dim>::exchanged_local_cells() const
  {
    return InterleavedExchange::packed_indices(*cell_partitioner);
  }

  template <int dim>
  template <typename Real>
  void BackgroundGrid<dim>::sum_local_cells(Real *const *arrays, const int count) const
  {
    if (n_ranks > 1)
      cell_exchange.sum(cell_partitioner, arrays, count);
  }

  template <int dim>
  template <typename Real>
  void BackgroundGrid<dim>::sum_packed_nodes(Real *values, const int count) const
  {
    if (n_ranks > 1)
      node_exchange.sum_packed(partitioner, values, count);
  }

  template <int dim>
  template <typename Real>
  void BackgroundGrid<dim>::sum_packed_cells(Real *values, const int count) const
  {
    if (n_ranks > 1)
      cell_exchange.sum_packed(cell_partitioner, values, count);
  }

  namespace
  {
    template <typename Real>
    std::vector<Real> &buffer_of(std::vector<double> &d, std::vector<float> &f);
    template <>
    std::vector<double> &buffer_of<double>(std::vector<double> &d, std::vector<float> &)
    {
      return d;
    }
    template <>
    std::vector<float> &buffer_of<float>(std::vector<double> &, std::vector<float> &f)
    {
      return f;
    }
  } // namespace

  // The Partitioner's raw-array exchange (InterleavedExchange), as
  // LinearAlgebra::distributed::Vector's compress(add) + update_ghost_values() do
  // internally, but without the vector's ghosted/non-ghosted state (writing into ghost
  // entries of a vector in the ghosted state and then compressing is what deal.II forbids):
  //   import: ghost entries are added into their owners' entries, then zeroed;
  //   export: owners' sums are copied into every rank's ghost entries.
  template <int dim>
  template <typename Real>
  void BackgroundGrid<dim>::sum_nodal(Real *const *arrays, const int count) const
  {
    if (n_ranks == 1)
      return;
    node_exchange.sum(partitioner, arrays, count);
  }

  // Cells: gather the owned and ghost cells' entries into the partitioner's layout,
  // exchange as for the nodes, scatter back. Each rank's cell sums then hold all points
  // of the cell, on whichever rank they are.
  template <int dim>
  template <typename Real>
  void BackgroundGrid<dim>::sum_cells(Real *const *arrays, const int count) const
  {
    if (n_ranks == 1)
      return;
    const std::size_t  n_local = lattice_cell_of_local_cell_index.size();
    std::vector<Real> &buffer  = buffer_of<Real>(cell_buffer_double, cell_buffer_float);
    buffer.resize(count * n_local);
    std::vector<Real *> local(count);
    for (int i = 0; i < count; ++i)
      {
        local[i] = buffer.data() + i * n_local;
        for (std::size_t c = 0; c < n_local; ++c)
          local[i][c] = lattice_cell_of_local_cell_index[c] < 0 ? Real(0) : arrays[i][lattice_cell_of_local_cell_index[c]];
      }
    cell_exchange.sum(cell_partitioner, local.data(), count);
    for (int i = 0; i < count; ++i)
      for (std::size_t c = 0; c < n_local; ++c)
        if (lattice_cell_of_local_cell_index[c] >= 0) // not a coarse cell's
          arrays[i][lattice_cell_of_local_cell_index[c]] = local[i][c];
  }

  template class BackgroundGrid<2>;
  template class BackgroundGrid<3>;
  template HostGrid<2, double> lattice_geometry<2>(const Parameters &);
  template HostGrid<3, double> lattice_geometry<3>(const Parameters &);
  template HostGrid<2, double> lattice_grid<2>(const Parameters &, bool);
  template HostGrid<3, double> lattice_grid<3>(const Parameters &, bool);
  template void BackgroundGrid<2>::sum_nodal(double *const *, int) const;
  template void BackgroundGrid<3>::sum_nodal(double *const *, int) const;
  template void BackgroundGrid<2>::sum_nodal(float *const *, int) const;
  template void BackgroundGrid<3>::sum_nodal(float *const *, int) const;
  template void BackgroundGrid<2>::sum_local_cells(double *const *, int) const;
  template void BackgroundGrid<3>::sum_local_cells(double *const *, int) const;
  template void BackgroundGrid<2>::sum_cells(double *const *, int) const;
  template void BackgroundGrid<3>::sum_cells(double *const *, int) const;
  template void BackgroundGrid<2>::sum_cells(float *const *, int) const;
  template void BackgroundGrid<3>::sum_cells(float *const *, int) const;
  template void BackgroundGrid<2>::sum_packed_nodes(double *, int) const;
  template void BackgroundGrid<3>::sum_packed_nodes(double *, int) const;
  template void BackgroundGrid<2>::sum_packed_nodes(float *, int) const;
  template void BackgroundGrid<3>::sum_packed_nodes(float *, int) const;
  template void BackgroundGrid<2>::sum_packed_cells(double *, int) const;
  template void BackgroundGrid<3>::sum_packed_cells(double *, int) const;
  template void BackgroundGrid<2>::sum_packed_cells(float *, int) const;
  template void BackgroundGrid<3>::sum_packed_cells(float *, int) const;
} // namespace mpm
