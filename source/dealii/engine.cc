#include <mpm/core/backend/cpu_backend.h>
#include <mpm/core/migration.h>
#include <mpm/core/precision.h>
#include <mpm/dealii/cuda_engine.h>
#include <mpm/dealii/engine.h>

#include <deal.II/base/exceptions.h>

#include <algorithm>
#include <type_traits>

namespace mpm
{
  namespace
  {
    // Several ranks with the pressure averaging's cell sums at each cell's lowest vertex (the
    // nodes near the material): summed over the ranks as the nodal sums are. The vertex is a
    // node of every rank whose points reach the cell.
    template <typename Exchange>
    struct CellSumsAtNodes
    {
      Exchange nodes;
      template <typename Real>
      void sum_nodal(Real *const *arrays, const int count) const
      {
        nodes.sum_nodal(arrays, count);
      }
      template <typename Real>
      void sum_cells(Real *const *arrays, const int count) const
      {
        nodes.sum_nodal(arrays, count);
      }
    };

    // Real: the type the points, the nodes and the step are in (double, or float with
    // Backend/Precision = float: built-in materials; the interface stays in double and the
    // engine converts where points, settings and totals cross it).
    template <int dim, typename Real = double>
    class CpuEngine : public Engine<dim>
    {
    public:
      // One rank: the engine's own nodes on the lattice, no exchange. With active_block_cells
      // > 0 only those near the material (active_nodes.h), chosen when points are loaded and
      // by refresh_active_nodes(); their boundary masks come from the lattice's faces.
      CpuEngine(const HostGrid<dim, double> &lattice, const std::vector<MaterialParameters<double>> &materials,
                const ShapeFunction shape, const int active_block_cells)
        : materials(converted<Real>(materials))
        , shape(shape)
      {
        for (int d = 0; d < dim; ++d)
          lattice_origin[d] = lattice.origin[d];
        lattice_h = lattice.h;
        if (active_block_cells == 0)
          {
            own_nodes = converted<Real>(lattice);
            own_nodes.allocate_cells();
            return;
          }
        this->near_material.block_cells              = active_block_cells;
        this->near_material.shape                    = shape;
        own_nodes.faces = lattice.faces;
        own_nodes.h     = lattice.h;
        for (int d = 0; d < dim; ++d)
          {
            own_nodes.origin[d]  = lattice.origin[d];
            own_nodes.n_cells[d] = lattice.n_cells[d];
          }
        for (int f = 0; f < 2 * dim; ++f)
          own_nodes.friction_coefficient[f] = lattice.friction_coefficient[f];
      }

      // Several ranks: the nodes are the grid's local ones (owned, then ghosts), summed over
      // ranks through its partitioner: in double the grid's vectors themselves, in float the
      // engine's own arrays in the same numbering (shared_view). With active_block_cells > 0
      // the node loops visit only the nodes near the material (choose_listed_nodes).
      CpuEngine(BackgroundGrid<dim> &grid, const std::vector<MaterialParameters<double>> &materials,
                const ShapeFunction shape, const int active_block_cells)
        : shared_grid(&grid)
        , materials(converted<Real>(materials))
        , shape(shape)
      {
        own_nodes.h = grid.h;
        for (int d = 0; d < dim; ++d)
          {
            own_nodes.origin[d]  = grid.origin[d];
            own_nodes.n_cells[d] = grid.n_cells[d];
          }
        this->near_material.block_cells = active_block_cells;
        this->near_material.shape       = shape;
        if (active_block_cells == 0)
          own_nodes.allocate_cells(); // the pressure averaging's cell sums; near the material at the nodes
      }

      void load(const MaterialPoints<dim> &p) override
      {
        auto new_labels = std::make_shared<PointLabels<dim>>();
        if constexpr (std::is_same_v<Real, double>)
          p.copy_to(points, &home_cells, new_labels.get());
        else
          {
            HostPoints<dim, double> given;
            p.copy_to(given, &home_cells, new_labels.get());
            convert_points(given, points);
          }
        put_in_cell_order(*new_labels);
        labels = std::move(new_labels); // a snapshot being written keeps the old ones
        // New points: the scatter's slabs are built anew for them, as in a new engine (a
        // run resumed from a checkpoint then sums in the order of the run that wrote it).
        backend.forget_grouping();
        if (this->follows_material())
          refresh_active_nodes();
      }

      // Several ranks: the points by lattice cell, by id within a cell, whatever order the
      // handler gave them in. The handler lists cells by their index in deal.II's
      // triangulation, which depends on the partitions the grid went through: a run resumed
      // from a checkpoint held the same points in another order and summed them in another
      // order (doc/log.md, 2026-12-02). handler_index maps the engine's order back to the
      // handler's for store().
      void put_in_cell_order(PointLabels<dim> &new_labels)
      {
        handler_index.clear();
        if (shared_grid == nullptr || shared_grid->n_ranks == 1) // one rank: one grid's history
          return;
        const int n = points.size();
        handler_index.resize(n);
        for (int i = 0; i < n; ++i)
          handler_index[i] = i;
        std::sort(handler_index.begin(), handler_index.end(), [&](const int a, const int b) {
          return home_cells[a] != home_cells[b] ? home_cells[a] < home_cells[b] :
                                                  new_labels.id[a] < new_labels.id[b];
        });
        for_each_point_array<dim>(points, points, [&](auto &array, auto &) { gather(array, handler_index); });
        gather(home_cells, handler_index);
        gather(new_labels.id, handler_index);
        for (int d = 0; d < dim; ++d)
          gather(new_labels.initial_position[d], handler_index);
      }

      // array[k] <- array[order[k]]
      template <typename Array>
      static void gather(Array &array, const std::vector<int> &order)
      {
        const Array copy = array;
        for (std::size_t k = 0; k < order.size(); ++k)
          array[k] = copy[order[k]];
      }

      void load(const HostPoints<dim, double> &p, std::shared_ptr<const PointLabels<dim>> new_labels) override
      {
        convert_points(p, points);
        home_cells.clear(); // asked for on several ranks (loaded from the handler) and below
        handler_index.clear();
        labels = std::move(new_labels);
        backend.forget_grouping();
        if (this->follows_material())
          refresh_active_nodes();
      }

      // The nodes near the points as they are now; their nodal sums start from zero, as
      // every step's do. Every point's home cell becomes its current cell.
      void refresh_active_nodes() override
      {
        if (!this->follows_material())
          return;
        const auto &near = this->near_material;
        if (!chooser)
          chooser = std::make_unique<NodeBlockChooser<dim>>(own_nodes.n_cells, near.block_cells);
        if (shared_grid != nullptr)
          return choose_listed_nodes();
        choose_nodes_near_material(near.block_cells, [&]() {
          chooser->choose(blocks_holding_points<dim>(own_nodes.origin, own_nodes.h, own_nodes.n_cells,
                                                     near.block_cells, points.view(), &home_cells));
        });
        // As on the GPU: the box around the kept blocks where it is compact (a stencil's nodes
        // are then one index plus offsets, as on every node's grid), else the block table.
        numbered_by_box = box_of_kept_blocks<dim>(own_nodes.n_cells, near.block_cells, chooser->kept_blocks(), box);
        if (numbered_by_box)
          lattice_of_box_node = lattice_of_box_nodes<dim>(own_nodes.n_cells, box);
        const std::vector<long> &lattice_of_node = lattice_of_kept_node();
        const long               n               = static_cast<long>(lattice_of_node.size());
        own_nodes.allocate_nodes(static_cast<int>(n));
        kept_node_boundary_masks<dim>(own_nodes.faces, own_nodes.n_cells, lattice_of_node, own_nodes.fixed_components,
                                      own_nodes.friction_faces);
        own_nodes.cell_volume.assign(n, 0.0); // the cells' sums at their lowest vertex
        own_nodes.cell_pressure_volume.assign(n, 0.0);
        this->near_material.kept(n, numbered_by_box);
      }

      // Several ranks: every rank keeps the node blocks around the cell blocks that hold a
      // point on any rank (each rank's list, gathered and merged: blocks_of_every_rank), so that the owner of
      // a node zeroes and updates it wherever another rank's points add into it. The arrays
      // are those of the rank's fine cells of deal.II's grid (fine within two blocks of the
      // points, BackgroundGrid::coarse_away_from_material); the node loops visit the kept
      // nodes (GridView::node_list), and a node no longer kept is zeroed (the grid files read
      // them).
      // The blocks are those of the points' home cells, from which the re-sorts measure how
      // far the points have gone: re-sorted at most the shape's safe distance out, well
      // inside the margin. Collective: load() runs on every rank.
      void choose_listed_nodes()
      {
        const int B = this->near_material.block_cells;
        AssertThrow(home_cells.size() == static_cast<std::size_t>(points.size()),
                    dealii::ExcMessage("Internal: the home cells are known only for points loaded from the "
                                       "ParticleHandler."));
        std::vector<long> own; // (the points come by lattice cell: few repeats kept)
        const auto        view = points.view();
        for (int i = 0; i < view.n_points; ++i)
          if (const long b = block_of_cell<dim>(home_cells[i], own_nodes.n_cells, B);
              view.material[i] >= 0 && (own.empty() || own.back() != b))
            own.push_back(b);
        const std::vector<long> blocks = blocks_of_every_rank(std::move(own), shared_grid->communicator);
        choose_nodes_near_material(B, [&]() { chooser->choose(blocks); });

        GridView<dim, Real> g      = shared_view(); // (float: its arrays made for a new partition)
        const bool          same   = listed_for == shared_grid->partitioner;
        std::vector<int>    before = std::move(listed_nodes);
        listed_nodes.clear();
        for (const long lattice : chooser->nodes().lattice_of_node)
          if (const int node = lattice >= 0 ? g.node_of_lattice(lattice) : -1; node >= 0)
            listed_nodes.push_back(node);
        std::sort(listed_nodes.begin(), listed_nodes.end());
        if (same) // the arrays hold the last steps' values: zero the nodes left out now
          {
            std::vector<bool> kept(g.n_nodes, false);
            for (const int n : listed_nodes)
              kept[n] = true;
            for (const int n : before)
              if (!kept[n])
                {
                  g.mass[n] = 0;
                  for (int d = 0; d < dim; ++d)
                    g.momentum[d][n] = g.force[d][n] = g.velocity[d][n] = 0;
                }
          }
        else // a new partition: new arrays, zero
          {
            own_nodes.cell_volume.assign(g.n_nodes, 0.0);
            own_nodes.cell_pressure_volume.assign(g.n_nodes, 0.0);
            listed_for = shared_grid->partitioner;
          }
        this->near_material.kept(static_cast<long>(dealii::Utilities::MPI::sum(double(listed_nodes.size()),
                                                                               shared_grid->communicator)));
      }

      void cells_with_mass(typename GridSnapshot<dim>::LatticeCells &out) override
      {
        AssertThrow(this->follows_material(),
                    dealii::ExcMessage("Internal: cells_with_mass() needs Nodes = near material."));
        out = lattice_cells_with_mass(own_view(), lattice_of_kept_node(), lattice_origin, lattice_h);
      }

      unsigned int store(MaterialPoints<dim> &p) override
      {
        unsigned int removed;
        if (!handler_index.empty())
          {
            // back in the handler's order (put_in_cell_order)
            HostPoints<dim, double> wide;
            convert_points(points, wide);
            for_each_point_array<dim>(wide, wide, [&](auto &array, auto &) {
              const auto copy = array;
              for (std::size_t k = 0; k < handler_index.size(); ++k)
                array[handler_index[k]] = copy[k];
            });
            removed = p.copy_from(wide);
          }
        else if constexpr (std::is_same_v<Real, double>)
          removed = p.copy_from(points);
        else
          {
            HostPoints<dim, double> wide;
            convert_points(points, wide);
            removed = p.copy_from(wide);
          }
        load(p); // the handler re-sorted them: take the new order
        return removed;
      }

      void snapshot(PointSnapshot<dim> &s) override
      {
        convert_points(points, s.points);
        s.labels = labels;
      }

      // Own nodes: copied into the grid's numbering. Shared ones are already there in double;
      // in float the own arrays are in the grid's numbering already.
      void nodal_to(BackgroundGrid<dim> &grid) override
      {
        if (shared_grid != nullptr)
          {
            if constexpr (!std::is_same_v<Real, double>)
              {
                const GridView<dim, double> to = grid.view();
                if (static_cast<int>(own_nodes.mass.size()) != to.n_nodes) // no step since a repartition
                  return;
                std::copy(own_nodes.mass.begin(), own_nodes.mass.end(), to.mass);
                for (int d = 0; d < dim; ++d)
                  std::copy(own_nodes.velocity[d].begin(), own_nodes.velocity[d].end(), to.velocity[d]);
              }
            return;
          }
        const GridView<dim, double> to = grid.view();
        const long                  n  = static_cast<long>(own_nodes.mass.size());
        if (this->follows_material()) // the others are zero (no mass, no velocity)
          {
            std::fill(to.mass, to.mass + to.n_nodes, 0.0);
            for (int d = 0; d < dim; ++d)
              std::fill(to.velocity[d], to.velocity[d] + to.n_nodes, 0.0);
          }
        for (long l = 0; l < n; ++l)
          {
            const long lattice = this->follows_material() ? lattice_of_kept_node()[l] : l;
            if (lattice < 0) // a kept block's node beyond the lattice
              continue;
            const int node = to.node_of_lattice(lattice);
            to.mass[node]  = own_nodes.mass[l];
            for (int d = 0; d < dim; ++d)
              to.velocity[d][node] = own_nodes.velocity[d][l];
          }
      }

      double max_distance_outside_home_cells() override
      {
        AssertThrow(home_cells.size() == static_cast<std::size_t>(points.size()),
                    dealii::ExcMessage("Internal: the home cells are known only for points loaded from the "
                                       "ParticleHandler."));
        const auto   view = points.view();
        const long  *home = home_cells.data();
        const auto  &g    = own_nodes;
        return backend.reduce_points(
          view.n_points, 0.0,
          [&](const int i) {
            return view.material[i] < 0 ? 0.0 :
                                          double(distance_outside_home_cell<dim>(g.origin, g.h, g.n_cells,
                                                                                 view.position, home[i], i));
          },
          [](const double a, const double b) { return a > b ? a : b; });
      }

      StepReduction<double> step(const StepSettings<dim, double> &s, const double dt) override
      {
        if (shared_grid == nullptr)
          {
            GridView<dim, Real> g = own_view();
            if (this->follows_material())
              g.cell_sums_at_nodes = true;
            else
              g.lattice_to_node = nullptr; // lattice order: a node's index is its lattice index
            return converted<double>(explicit_step<dim>(backend, shape, g, points.view(), materials.data(),
                                                        converted<Real>(s), static_cast<Real>(dt),
                                                        NoGridExchange()));
          }
        if (this->follows_material())
          {
            GridView<dim, Real> g = shared_view();
            g.node_list           = listed_nodes.data();
            g.n_listed            = static_cast<int>(listed_nodes.size());
            g.cell_sums_at_nodes  = true;
            return converted<double>(explicit_step<dim>(backend, shape, g, points.view(), materials.data(),
                                                        converted<Real>(s), static_cast<Real>(dt),
                                                        CellSumsAtNodes<typename BackgroundGrid<dim>::Exchange>{
                                                          shared_grid->exchange()}));
          }
        return converted<double>(explicit_step<dim>(backend, shape, shared_view(), points.view(), materials.data(),
                                                    converted<Real>(s), static_cast<Real>(dt),
                                                    shared_grid->exchange()));
      }

      // Summed in double whatever the points are in.
      PointTotals<dim, double> totals() override
      {
        return point_totals<dim, Real, CpuBackend, double>(backend, points.view());
      }

      double relative_mass_round_off() const override { return relative_mass_round_off_of<Real>(); }

      long n_points() const override { return points.size(); }

      void set_materials(const std::vector<MaterialParameters<double>> &m) override { materials = converted<Real>(m); }

    private:
      // Several ranks: the grid's lattice lookup, boundary masks and local numbering; the nodal
      // arrays its vectors (double) or the own ones (float: reallocated, zero, when a
      // repartition renumbered the nodes, as the grid's vectors are); the own cell sums.
      GridView<dim, Real> shared_view()
      {
        const GridView<dim, double> grid = shared_grid->view();
        GridView<dim, Real>         g;
        if constexpr (std::is_same_v<Real, double>)
          g = grid;
        else
          {
            if (shared_grid->partitioner != nodes_built_for)
              {
                own_nodes.allocate_nodes(grid.n_nodes);
                nodes_built_for = shared_grid->partitioner;
              }
            g = make_grid_view<dim, Real>(own_nodes);
            g.lattice_to_node  = grid.lattice_to_node;
            for (int d = 0; d < dim; ++d)
              {
                g.box_lower[d] = grid.box_lower[d];
                g.box_nodes[d] = grid.box_nodes[d];
              }
            g.n_nodes          = grid.n_nodes;
            g.fixed_components = grid.fixed_components;
            g.friction_faces   = grid.friction_faces;
            for (int f = 0; f < 2 * dim; ++f)
              g.friction_coefficient[f] = static_cast<Real>(grid.friction_coefficient[f]);
          }
        g.cell_volume          = own_nodes.cell_volume.data();
        g.cell_pressure_volume = own_nodes.cell_pressure_volume.data();
        return g;
      }

      // The own nodes' view; near the material, numbered as the box around them or through
      // the chooser's block table.
      GridView<dim, Real> own_view()
      {
        GridView<dim, Real> g = make_grid_view<dim, Real>(own_nodes);
        if (chooser && numbered_by_box)
          {
            g.lattice_to_node = nullptr;
            for (int d = 0; d < dim; ++d)
              {
                g.box_lower[d] = box.lower[d];
                g.box_nodes[d] = box.nodes[d];
              }
          }
        else if (chooser)
          {
            const NodeBlocks<dim> &blocks = chooser->nodes();
            g.set_block_table(blocks.block_slot.data(), blocks.block_cells, blocks.node_blocks);
          }
        return g;
      }

      // One rank: the nodes and the cell sums. Several ranks: the lattice geometry and the cell
      // sums; the nodes are shared_grid's vectors in double, in float the arrays here in their
      // numbering (shared_view).
      HostGrid<dim, Real>                     own_nodes;
      BackgroundGrid<dim>                    *shared_grid = nullptr;
      std::shared_ptr<const dealii::Utilities::MPI::Partitioner> nodes_built_for; // float on several ranks
      std::unique_ptr<NodeBlockChooser<dim>>  chooser; // nodes near the material: their block table
      bool                                    numbered_by_box = false; // or as the box around them:
      NodeBox<dim>                            box;
      std::vector<long>                       lattice_of_box_node;
      // Several ranks, nodes near the material: the local nodes kept, ascending, and the
      // partition they were chosen in (the cell sums sit at the nodes then).
      std::vector<int>                                           listed_nodes;
      std::shared_ptr<const dealii::Utilities::MPI::Partitioner> listed_for;

      const std::vector<long> &lattice_of_kept_node() const
      {
        return numbered_by_box ? lattice_of_box_node : chooser->nodes().lattice_of_node;
      }
      std::vector<MaterialParameters<Real>>   materials;
      ShapeFunction                           shape;
      double lattice_origin[dim] = {}, lattice_h = 0; // one rank: the lattice's geometry in double (output)
      CpuBackend                              backend;
      HostPoints<dim, Real>                   points;
      std::vector<long>                       home_cells; // lattice cell of each point at the last sort
      std::vector<int>                        handler_index; // several ranks: point k is the handler's handler_index[k]
      std::shared_ptr<const PointLabels<dim>> labels;     // id, initial position, in the order of points
    };
  } // namespace

  namespace
  {
    // Parameters::parse refuses these with the entry's name; a program calling make_engine
    // directly gets the same reason.
    void refuse_user_materials_in_float(const std::vector<MaterialParameters<double>> &materials)
    {
      for (const MaterialParameters<double> &m : materials)
        AssertThrow(m.model != MaterialModel::user_defined,
                    dealii::ExcMessage("Backend/Precision = float: a material defined outside the library steps "
                                       "in double only."));
    }
  } // namespace

  void check_backend(const std::string &backend)
  {
    AssertThrow(backend == "cpu" || (backend == "cuda" && cuda_engine_built()),
                dealii::ExcMessage("Parameter 'Backend/Backend': '" + backend +
                                   "' is not available in this build (allowed here: cpu). Build with "
                                   "-DMPM_WITH_CUDA=ON for cuda."));
  }

  template <int dim>
  std::unique_ptr<Engine<dim>> make_engine(const std::string &backend, const HostGrid<dim, double> &lattice,
                                           const std::vector<MaterialParameters<double>> &materials,
                                           const ShapeFunction shape, const int active_block_cells,
                                           const bool single_precision)
  {
    check_backend(backend);
    if (single_precision)
      {
        refuse_user_materials_in_float(materials);
        if (backend == "cpu")
          return std::make_unique<CpuEngine<dim, float>>(lattice, materials, shape, active_block_cells);
      }
    if (backend == "cuda") // throws where no device is found
      return make_cuda_engine<dim>(lattice, materials, shape, active_block_cells, single_precision);
    return std::make_unique<CpuEngine<dim>>(lattice, materials, shape, active_block_cells);
  }

  template <int dim>
  std::unique_ptr<Engine<dim>> make_engine(const std::string &backend, BackgroundGrid<dim> &grid,
                                           const std::vector<MaterialParameters<double>> &materials,
                                           const ShapeFunction shape, const bool single_precision,
                                           const int active_block_cells)
  {
    check_backend(backend);
    if (single_precision)
      {
        refuse_user_materials_in_float(materials);
        if (backend == "cpu")
          return std::make_unique<CpuEngine<dim, float>>(grid, materials, shape, active_block_cells);
      }
    if (backend == "cuda") // throws where a rank finds no device; keeps every node of its part
      return make_cuda_engine<dim>(grid, materials, shape, single_precision);
    return std::make_unique<CpuEngine<dim>>(grid, materials, shape, active_block_cells);
  }

  template std::unique_ptr<Engine<2>> make_engine(const std::string &, const HostGrid<2, double> &,
                                                  const std::vector<MaterialParameters<double>> &, ShapeFunction, int,
                                                  bool);
  template std::unique_ptr<Engine<3>> make_engine(const std::string &, const HostGrid<3, double> &,
                                                  const std::vector<MaterialParameters<double>> &, ShapeFunction, int,
                                                  bool);
  template std::unique_ptr<Engine<2>> make_engine(const std::string &, BackgroundGrid<2> &,
                                                  const std::vector<MaterialParameters<double>> &, ShapeFunction,
                                                  bool, int);
  template std::unique_ptr<Engine<3>> make_engine(const std::string &, BackgroundGrid<3> &,
                                                  const std::vector<MaterialParameters<double>> &, ShapeFunction,
                                                  bool, int);
} // namespace mpm
