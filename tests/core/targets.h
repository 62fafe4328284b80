// Where a test scene runs: a Target owns the storage its backend needs and hands out the
// views; finish() brings points and nodal values back into the host owners. Test
// drivers are templated on the Target, so the CPU test and its GPU twin (tests/gpu,
// CudaTarget in gpu_targets.h) run the same host code around the same step.h.
#pragma once

#include <mpm/core/backend/cpu_backend.h>
#include <mpm/core/host_storage.h>
#include <mpm/core/material/material.h>

#include <vector>

namespace mpm_test
{
  template <int dim, typename Real>
  struct CpuTarget
  {
    static constexpr const char *name = "cpu";
    mpm::HostGrid<dim, Real>                   &host_grid;
    mpm::HostPoints<dim, Real>                 &host_points;
    std::vector<mpm::MaterialParameters<Real>> materials;
    mpm::CpuBackend                             backend;

    CpuTarget(mpm::HostGrid<dim, Real> &g, mpm::HostPoints<dim, Real> &p,
              const std::vector<mpm::MaterialParameters<Real>> &m)
      : host_grid(g)
      , host_points(p)
      , materials(m)
    {}
    mpm::GridView<dim, Real>             grid() { return host_grid.view(); }
    mpm::PointsView<dim, Real>           points() { return host_points.view(); }
    // The points for step `step` (a GPU target may reorder them between steps).
    template <typename Shape>
    mpm::PointsView<dim, Real> points_at_step(const long /*step*/)
    {
      return points();
    }
    const mpm::MaterialParameters<Real> *material_table() const { return materials.data(); }
    void                                 finish() {}
  };
} // namespace mpm_test
