#include <mpm/dealii/background_grid.h>
#include <mpm/core/active_nodes.h>

#include "lattice_box.h"

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
  using namespace grid_detail;

  namespace
  {
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

  template class BackgroundGrid<2>;
  template class BackgroundGrid<3>;
  template HostGrid<2, double> lattice_geometry<2>(const Parameters &);
  template HostGrid<3, double> lattice_geometry<3>(const Parameters &);
  template HostGrid<2, double> lattice_grid<2>(const Parameters &, bool);
  template HostGrid<3, double> lattice_grid<3>(const Parameters &, bool);
} // namespace mpm
