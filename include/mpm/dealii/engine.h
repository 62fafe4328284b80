// Where the MPM step runs. The simulator hands points over at the start and takes
// them back (store) only when the ParticleHandler must see them (MPI re-sort and
// repartition, end of run); in between, the engine keeps them in the backend's arrays.
// Output reads a snapshot of those arrays instead, with no hand-over. CPU here; the
// CUDA engine implements the same interface over device arrays.
#pragma once

#include <mpm/core/diagnostics.h>
#include <mpm/core/step.h>
#include <mpm/dealii/material_points.h>

#include <limits>
#include <memory>
#include <string>
#include <vector>

namespace mpm
{
  template <int dim>
  class Engine
  {
  public:
    virtual ~Engine() = default;
    virtual void                    load(const MaterialPoints<dim> &points)           = 0;
    virtual unsigned int            store(MaterialPoints<dim> &points)                = 0;
    virtual StepReduction<double>   step(const StepSettings<dim, double> &s, double dt) = 0;
    virtual PointTotals<dim, double> totals()                                         = 0;
    // For output: copies the points as they are now into snapshot.points (engine order,
    // points that left the grid included with material < 0), sets snapshot.labels, and
    // brings the grid's nodal vectors up to date (mass, velocity) where the engine keeps
    // its own copy. The handler is not touched.
    virtual void snapshot(PointSnapshot<dim> &snapshot) = 0;
    // Largest distance of a point outside the cell it was sorted into at the last
    // load/store, in cell units (max-norm); MPI runs re-sort before it gets unsafe.
    // An engine that does not track it makes MPI runs re-sort after every step.
    virtual double max_distance_outside_home_cells() { return std::numeric_limits<double>::infinity(); }
    // Steps between re-sorts of the points (Backend/Sort interval); engines that do not
    // re-sort ignore it.
    virtual void set_sort_interval(int /*steps*/) {}
    // Replaces the material table (e.g. when plasticity is switched on).
    virtual void set_materials(const std::vector<MaterialParameters<double>> &materials) = 0;
  };

  // Throws naming Backend/Backend if the requested backend is not available.
  template <int dim>
  std::unique_ptr<Engine<dim>> make_engine(const std::string &backend, BackgroundGrid<dim> &grid,
                                           const std::vector<MaterialParameters<double>> &materials,
                                           ShapeFunction shape);
} // namespace mpm
