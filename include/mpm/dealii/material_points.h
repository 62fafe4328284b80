// Material points in deal.II's ParticleHandler: the property layout (declared once,
// by name, so that output shows every property under its own name), generation
// from the prm bodies, and the copies between the handler and the core's arrays.
#pragma once

#include <mpm/core/host_storage.h>
#include <mpm/dealii/background_grid.h>
#include <mpm/dealii/parameters.h>
#include <mpm/dealii/property_layout.h>

#include <deal.II/numerics/data_component_interpretation.h>
#include <deal.II/particles/particle_handler.h>

#include <boost/signals2/connection.hpp>

#include <functional>
#include <memory>

#include <string>
#include <vector>

namespace mpm
{
  // What the core's arrays do not hold but output needs, per point in the engine's
  // order: the particle id and the initial position. Taken from the handler at each
  // load (the engine's order changes only there).
  template <int dim>
  struct PointLabels
  {
    std::vector<dealii::types::particle_index> id;
    std::vector<double>                        initial_position[dim];
    // The names of the points' state variables (PropertyLayout::state_variables on).
    std::vector<std::string> state_variable_names;
  };

  // A copy of the points as the engine holds them at one time, for output without a
  // hand-over to the ParticleHandler: the core's arrays (points that left the grid have
  // material < 0 and are skipped) and their labels.
  template <int dim>
  struct PointSnapshot
  {
    HostPoints<dim, double>                  points;
    std::shared_ptr<const PointLabels<dim>> labels;
    // Set while the points are still on their way (Engine::start_snapshot): fills them.
    std::function<void()> arrival;

    // Waits for the points where they are still on their way; then they can be read.
    void wait_for_points()
    {
      if (arrival)
        {
          const auto arrive = std::move(arrival);
          arrival           = nullptr;
          arrive();
        }
    }

    // Property array of point i in the handler's layout: the values the handler would hold
    // after a hand-over. values holds layout.n_properties() entries.
    void properties(const PropertyLayout<dim> &layout, int i, double *values) const;

    // The layout of these points' properties.
    PropertyLayout<dim> layout() const { return PropertyLayout<dim>(points.fields, labels->state_variable_names); }

    // The points i for which keep(i) holds, with their labels, in their order.
    PointSnapshot selected(const std::function<bool(int)> &keep) const;
  };

  // The message of points whose number of state variables is not the run's (names).
  std::string state_variable_count_mismatch(int given, const std::vector<std::string> &names);

  // The points of one body with their initial stress and material field value.
  template <int dim>
  struct GeneratedBody
  {
    HostPoints<dim, double> points;
  };

  // Every body's points from the prm on the lattice of the background grid
  // (lattice_geometry). It needs no deal.II grid, so the simulator runs it on a thread
  // while the grid is built.
  template <int dim>
  std::vector<GeneratedBody<dim>> generate_bodies(const Parameters &parameters);

  // The bodies' points as the core's arrays, with their labels, exactly as
  // MaterialPoints::insert followed by copy_to gives them on one rank, and like them
  // cell by cell (lattice cells of `lattice`, in lattice order; the handler's cells are in
  // deal.II's order), in generation order within a cell. The ids are the generation
  // index, as insert gives them. One-rank runs load their engine from this while deal.II
  // builds the grid and the handler.
  template <int dim>
  void points_of_bodies(const std::vector<GeneratedBody<dim>> &bodies, const HostGrid<dim, double> &lattice,
                        HostPoints<dim, double> &points, PointLabels<dim> &labels);

  template <int dim>
  class MaterialPoints
  {
  public:
    // Also connects the cell weights of the load balance (Parallel/Point weight) to
    // the triangulation.
    MaterialPoints(BackgroundGrid<dim> &grid, const Parameters &parameters);

    // Fills the handler with the points of every body inside this rank's cells.
    void generate(const Parameters &parameters) { insert(generate_bodies<dim>(parameters)); }
    // The same from bodies generated beforehand.
    void insert(const std::vector<GeneratedBody<dim>> &bodies);

    // Handler -> core arrays (after generation and after every re-sort). If home_cells
    // is given, it receives the lattice index of each point's (locally owned) cell; if
    // labels is given, each point's id and initial position.
    void copy_to(HostPoints<dim, double> &points, std::vector<long> *home_cells = nullptr,
                 PointLabels<dim> *labels = nullptr) const;

    // Every rank's points at once (each rank gives the same `all`): the handler's points
    // are replaced by those of `all` that lie in this rank's cells, with their ids and
    // initial positions from all.labels; points with material < 0 are left out. Unlike
    // copy_from it moves points any distance (copy_from reaches only the ghost cells).
    void replace(const PointSnapshot<dim> &all);

    // Core arrays -> handler: positions and properties; points the core marked as
    // having left the grid are removed. Then the handler re-sorts points into cells
    // and ranks (points now in another rank's cell migrate there with all their
    // properties). Returns the number of points removed on this rank.
    unsigned int copy_from(const HostPoints<dim, double> &points);

    // Largest work of one rank over the mean (1 = perfectly balanced), work being the
    // partition's weights: owned cells (with points only, where empty cells cost nothing:
    // empty_cells_cost) + Point weight x owned points.
    double imbalance() const;
    // The same with this rank's number of points given (an engine that re-sorts without
    // the handler knows it; the handler's count is then out of date).
    double imbalance(double n_local_points) const;

    // Repartitions the triangulation by work (cell weight 1 + Point weight x points in
    // the cell), moves the points with their cells, and rebuilds the grid's nodes.
    void repartition();

    // Where deal.II's grid is coarse away from the material (several ranks, Grid/Nodes =
    // near material, CPU): refines it where its fine region misses a block around the
    // points (BackgroundGrid::fine_region_misses), the points moving with their cells and
    // the partition following the work, and distributes the nodes again. Whether it did
    // (collective; the engine must then load the points again). before_refining runs first
    // where it does (a grid output in flight must finish).
    bool refine_near_points(const std::function<void()> &before_refining = {});

    dealii::Particles::ParticleHandler<dim> handler;
    dealii::types::particle_index           n_generated = 0;
    // Points this rank handed to another rank in copy_from's re-sorts, summed.
    unsigned long n_sent = 0;

    // The names of the state variables every point carries (Parameters::state_variable_names).
    const std::vector<std::string> state_variable_names;
    // Where each field of the points sits in a particle's properties.
    const PropertyLayout<dim> layout;

  private:
    BackgroundGrid<dim> &grid;
    double                             point_weight;
    bool                               empty_cells_weigh = true; // empty_cells_cost (background_grid.h)
    boost::signals2::scoped_connection weight_connection;
  };
} // namespace mpm
