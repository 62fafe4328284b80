// The exchange overlapped with the points' passes (DeviceEngine on several ranks,
// exchange_overlap.h, explicit_step's pass_then_sum), on one device: an exchange whose
// entries are a band of lattice layers across the material (nodes and the averaging's cells)
// and whose sums over "the ranks" leave the values as they are (one rank). Packed, copied to
// the host, unpacked: a point of the second pass that added into an exchanged entry after the
// pack would have its contribution overwritten by the stale value, an error of order one.
//   - P1/V5 slump, 2 cells across (3D GIMP, 10,024 points), FLIP 0.99, pressure averaging
//     (MUSL: both nodal exchanges and the cell exchange overlapped), 60 steps of fixed dt;
//   - points, nodal mass and velocity against the CPU step within 1e-10 (reordered atomic sums
//     only, as test_gpu_device_engine), with the overlap and with MPM_CUDA_OVERLAP=0;
//   - the overlap happened: a share of the points strictly between 0 and 1 went first, and
//     three sums per step were made;
//   - the split's premise held: no point got as far as half a cell out of its home cell.
#include "../core/check.h"
#include "gpu_scenes.h"

#include <mpm/core/migration.h>
#include <mpm/cuda/device_engine.h>

#include <algorithm>
#include <cstdlib>

using namespace mpm;
using namespace mpm_test;

namespace
{
  // Lattice layers i0 .. i0 + 2 of nodes (i0 .. i0 + 1 of cells) exchanged with no other rank.
  class BandExchange : public mpm::cuda::NodalExchange
  {
  public:
    BandExchange(const int n_cells[3], const int i0)
    {
      for (int k = 0; k <= n_cells[2]; ++k)
        for (int j = 0; j <= n_cells[1]; ++j)
          for (int i = i0; i <= i0 + 2; ++i)
            nodes.push_back(i + (n_cells[0] + 1) * (j + (n_cells[1] + 1) * k));
      for (int k = 0; k < n_cells[2]; ++k)
        for (int j = 0; j < n_cells[1]; ++j)
          for (int i = i0; i <= i0 + 1; ++i)
            cells.push_back(i + n_cells[0] * (j + static_cast<long>(n_cells[1]) * k));
    }
    std::vector<int>  exchanged_nodes() const override { return nodes; }
    std::vector<long> exchanged_cells() const override { return cells; }
    void              sum_nodal(double *, int) override { ++n_sums; }
    void              sum_nodal(float *, int) override { ++n_sums; }
    void              sum_cells(double *, int) override { ++n_sums; }
    void              sum_cells(float *, int) override { ++n_sums; }
    long              n_sums = 0;

  private:
    std::vector<int>  nodes;
    std::vector<long> cells;
  };

  // Runs the scene on the device with the band exchange and against the CPU.
  void run(const bool overlap)
  {
    if (overlap)
      unsetenv("MPM_CUDA_OVERLAP");
    else
      setenv("MPM_CUDA_OVERLAP", "0", 1);
    const char *name = overlap ? "overlapped" : "not overlapped";

    HostGrid<3, double>                     grid;
    HostPoints<3, double>                   points;
    std::vector<MaterialParameters<double>> materials;
    mpm_bench::make_p1(2, grid, points, materials);
    StepSettings<3, double> s = mpm_bench::p1_settings<double>();
    s.damping                 = 0;
    s.flip_fraction           = 0.99;
    s.pressure_averaging      = true;
    const double dt           = mpm_bench::P1::cfl * mpm_bench::P1::h / mpm_bench::p1_wave_speed();
    const int    n_steps      = 60;

    // The band across the middle of the material along x; every point at home in its cell.
    std::vector<double> x(points.position[0].begin(), points.position[0].end());
    std::nth_element(x.begin(), x.begin() + x.size() / 2, x.end());
    const int         i0 = static_cast<int>((x[x.size() / 2] - grid.origin[0]) / grid.h) - 1;
    std::vector<long> home(points.size());
    for (int i = 0; i < points.size(); ++i)
      {
        const double p[3] = {points.position[0][i], points.position[1][i], points.position[2][i]};
        home[i]           = lattice_cell_containing<3>(grid.origin, grid.h, grid.n_cells, p);
      }

    BandExchange               exchange(grid.n_cells, i0);
    HostPoints<3, double>      cpu_points = points;
    CpuBackend                 cpu;
    mpm::cuda::DeviceEngine<3> engine(grid.view(), materials, ShapeFunction::gimp, &exchange);
    engine.upload_points(points);
    engine.set_home_cells(home);
    double time = 0;
    for (int step = 0; step < n_steps; ++step, time += dt)
      {
        mpm_bench::p1_gravity(s, time);
        explicit_step<3, GimpShape>(cpu, grid.view(), cpu_points.view(), materials.data(), s, dt);
        engine.step(s, dt);
      }
    const double outside = engine.max_distance_outside_home_cells();
    const double share   = engine.share_of_points_before_overlap();

    HostPoints<3, double> gpu_points;
    engine.download_points(gpu_points);
    HostGrid<3, double> gpu_grid = grid;
    engine.download_nodal(gpu_grid.view());
    double dx = 0, dv = 0, v_max = 0, dm = 0, m_max = 0, dvn = 0;
    for (int i = 0; i < points.size(); ++i)
      for (int d = 0; d < 3; ++d)
        {
          dx    = std::max(dx, std::abs(gpu_points.position[d][i] - cpu_points.position[d][i]) / grid.h);
          dv    = std::max(dv, std::abs(gpu_points.velocity[d][i] - cpu_points.velocity[d][i]));
          v_max = std::max(v_max, std::abs(cpu_points.velocity[d][i]));
        }
    for (std::size_t n = 0; n < grid.mass.size(); ++n)
      {
        dm    = std::max(dm, std::abs(gpu_grid.mass[n] - grid.mass[n]));
        m_max = std::max(m_max, grid.mass[n]);
        for (int d = 0; d < 3; ++d)
          dvn = std::max(dvn, std::abs(gpu_grid.velocity[d][n] - grid.velocity[d][n]));
      }
    std::printf("test_gpu_exchange_overlap (%s): %d points, band at layer %d, %d steps, %ld sums, points first %.3f, "
                "farthest out of home %.3f cells | x/h %.1e, v %.1e (max |v| %.2e), nodal mass %.1e, v %.1e\n",
                name, points.size(), i0, n_steps, exchange.n_sums, share, outside, dx, dv / v_max, v_max, dm / m_max,
                dvn / v_max);
    check(v_max > 1e-4, "the points move");
    check(exchange.n_sums == 3L * n_steps, "three sums per step (nodes twice, cells once)");
    if (overlap)
      check(share > 0 && share < 1, "the overlap split the points");
    else
      check(share < 0, "MPM_CUDA_OVERLAP=0: no split");
    check_below(outside, safe_distance_outside_home_cell(ShapeFunction::gimp), "distance out of the home cells");
    check_below(dx, 1e-10, "positions: DeviceEngine vs CPU (x/h)");
    check_below(dv / v_max, 1e-10, "velocities: DeviceEngine vs CPU (of max |v|)");
    check_below(dm / m_max, 1e-10, "nodal mass: DeviceEngine vs CPU");
    check_below(dvn / v_max, 1e-10, "nodal velocity: DeviceEngine vs CPU");
  }
} // namespace

int main()
{
  if (!cuda_device_present("test_gpu_exchange_overlap"))
    return skip_code;
  run(true);
  run(false);
  return finish("test_gpu_exchange_overlap");
}
