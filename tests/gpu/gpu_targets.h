// The GPU Target (CudaTarget) beside the CPU one of tests/core/targets.h, and helpers to
// compare a CPU and a GPU run of one scene point by point.
#pragma once

#include "../core/targets.h"

#include <mpm/core/backend/cuda_backend.h>
#include <mpm/core/backend/cuda_point_order.h>
#include <mpm/core/backend/cuda_storage.h>
#include <mpm/core/host_storage.h>
#include <mpm/core/step.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <random>
#include <vector>

namespace mpm_test
{
  // Exit code ctest reads as "skipped" (SKIP_RETURN_CODE 77 in tests/gpu/CMakeLists.txt).
  constexpr int skip_code = 77;

  // Prints the device, or returns false where there is none (the test then exits 77).
  inline bool cuda_device_present(const char *test_name)
  {
    if (mpm::cuda_device_count() == 0)
      {
        std::printf("%s: no CUDA device found, skipping\n", test_name);
        return false;
      }
    cudaDeviceProp prop;
    MPM_CUDA_CHECK(cudaGetDeviceProperties(&prop, 0));
    std::printf("%s: device %s (sm_%d%d, %d SMs)\n", test_name, prop.name, prop.major, prop.minor,
                prop.multiProcessorCount);
    return true;
  }

  // The option some GPU tests take, --short (a tenth of the steps or fewer, for compute-sanitizer's
  // racecheck, which does not finish them whole in minutes): true if given. Anything else gets a
  // usage line and the exit code 2 in *exit_code (else 0). Output from then on is line-buffered, so
  // that a sanitizer's log cut by a time limit shows how far the test came.
  inline bool short_form_option(const int argc, char **argv, const char *test_name, int *exit_code)
  {
    const bool given = argc == 2 && std::strcmp(argv[1], "--short") == 0;
    *exit_code       = argc > 1 && !given ? 2 : 0;
    if (*exit_code != 0)
      std::fprintf(stderr, "usage: %s [--short]\n", test_name);
    std::setvbuf(stdout, nullptr, _IOLBF, 0);
    return given;
  }

  template <int dim, typename Real>
  struct CudaTarget
  {
    static constexpr const char *name = "cuda";
    mpm::HostGrid<dim, Real>     &host_grid;
    mpm::HostPoints<dim, Real>   &host_points;
    mpm::DeviceGrid<dim, Real>    device_grid;
    mpm::DevicePoints<dim, Real>  device_points;
    mpm::DeviceMaterials<Real>    device_materials;
    mpm::CudaBackend              backend;

    mpm::PointOrder<dim, Real>    order;
    int                           sort_every = 0; // sort the points by stencil every n steps (0: never)

    CudaTarget(mpm::HostGrid<dim, Real> &g, mpm::HostPoints<dim, Real> &p,
               const std::vector<mpm::MaterialParameters<Real>> &m)
      : host_grid(g)
      , host_points(p)
    {
      device_grid.upload(g);
      // The pressure averaging's cell sums where the host grid has them (make_dense), which
      // DeviceGrid::upload leaves to the owner (DeviceEngine keeps its own).
      device_grid.cell_volume.upload(g.cell_volume);
      device_grid.cell_pressure_volume.upload(g.cell_pressure_volume);
      device_points.upload(p);
      device_materials.upload(m);
      order.reset(backend, device_points.size());
    }
    mpm::GridView<dim, Real>             grid() { return device_grid.view(); }
    mpm::PointsView<dim, Real>           points() { return device_points.view(); }
    template <typename Shape>
    mpm::PointsView<dim, Real> points_at_step(const long step)
    {
      if (sort_every > 0 && step % sort_every == 0)
        order.template sort<Shape>(backend, device_grid.view(), device_points);
      return points();
    }
    const mpm::MaterialParameters<Real> *material_table() const { return device_materials.data(); }
    // Points back to the host in the order they were uploaded.
    void finish()
    {
      backend.synchronize();
      order.download_in_reference_order(backend, device_points, host_points);
      device_grid.download_nodal(host_grid);
    }
  };

  // The same, with the points sorted by stencil every 7 steps (scatter_stencil then
  // sums runs of shared nodes; results must not change beyond rounding).
  template <int dim, typename Real>
  struct CudaSortedTarget : CudaTarget<dim, Real>
  {
    static constexpr const char *name = "cuda, sorted";
    CudaSortedTarget(mpm::HostGrid<dim, Real> &g, mpm::HostPoints<dim, Real> &p,
                     const std::vector<mpm::MaterialParameters<Real>> &m)
      : CudaTarget<dim, Real>(g, p, m)
    {
      this->sort_every = 7;
    }
  };

  // Per-point differences between two runs of one scene, each field scaled by a
  // magnitude of that field over the whole reference run (a per-component relative
  // error is meaningless where the component passes through zero):
  // positions by the cell size h, velocities by max |v|, stresses by max |sigma|.
  struct Difference
  {
    double position = 0, velocity = 0, stress = 0;
    int    removed_mismatch = 0;
    double worst() const
    {
      double w = position > velocity ? position : velocity;
      return w > stress ? w : stress;
    }
  };

  template <int dim, typename Real>
  Difference compare_points(const mpm::HostPoints<dim, Real> &ref, const mpm::HostPoints<dim, Real> &other,
                            const double h)
  {
    Difference diff;
    double     v_scale = 0, s_scale = 0;
    for (int i = 0; i < ref.size(); ++i)
      {
        for (int d = 0; d < dim; ++d)
          v_scale = std::max(v_scale, std::abs(double(ref.velocity[d][i])));
        for (int c = 0; c < mpm::n_voigt; ++c)
          s_scale = std::max(s_scale, std::abs(double(ref.stress[c][i])));
      }
    if (v_scale == 0)
      v_scale = 1;
    if (s_scale == 0)
      s_scale = 1;
    for (int i = 0; i < ref.size(); ++i)
      {
        if ((ref.material[i] < 0) != (other.material[i] < 0))
          ++diff.removed_mismatch;
        for (int d = 0; d < dim; ++d)
          {
            diff.position = std::max(diff.position, std::abs(double(ref.position[d][i] - other.position[d][i])) / h);
            diff.velocity = std::max(diff.velocity, std::abs(double(ref.velocity[d][i] - other.velocity[d][i])) / v_scale);
          }
        for (int c = 0; c < mpm::n_voigt; ++c)
          diff.stress = std::max(diff.stress, std::abs(double(ref.stress[c][i] - other.stress[c][i])) / s_scale);
        // NaN anywhere makes the comparison fail
        for (int d = 0; d < dim; ++d)
          if (!std::isfinite(double(other.position[d][i])) || !std::isfinite(double(other.velocity[d][i])))
            diff.position = diff.velocity = INFINITY;
      }
    return diff;
  }

  // The points in another order: entry k of the result is point order[k] of p (changes
  // the order of every nodal sum on the CPU).
  template <int dim, typename Real>
  mpm::HostPoints<dim, Real> permuted(const mpm::HostPoints<dim, Real> &p, const std::vector<int> &order)
  {
    mpm::HostPoints<dim, Real> r = p;
    mpm::for_each_point_array<dim>(r, p, [&](auto &to, const auto &from) {
      if (from.empty()) // an optional array (material_field) that the scene leaves out
        return;
      for (std::size_t k = 0; k < order.size(); ++k)
        to[k] = from[order[k]];
    });
    return r;
  }

  // The inverse of permuted(., order): back in the original order.
  inline std::vector<int> inverse_order(const std::vector<int> &order)
  {
    std::vector<int> inverse(order.size());
    for (std::size_t k = 0; k < order.size(); ++k)
      inverse[order[k]] = int(k);
    return inverse;
  }

  // The reversed order of n points.
  inline std::vector<int> reversed_order(const int n)
  {
    std::vector<int> order(n);
    for (int k = 0; k < n; ++k)
      order[k] = n - 1 - k;
    return order;
  }

  // A reproducible random order of n points (std::mt19937 is specified exactly by the
  // standard; the shuffle is written out because std::shuffle's algorithm is not).
  inline std::vector<int> random_order(const int n, const unsigned seed)
  {
    std::vector<int> order(n);
    for (int k = 0; k < n; ++k)
      order[k] = k;
    std::mt19937 random(seed);
    for (int k = n - 1; k > 0; --k)
      std::swap(order[k], order[random() % (k + 1)]);
    return order;
  }

} // namespace mpm_test
