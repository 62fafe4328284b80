// cuda::DeviceEngine (include/mpm/cuda/device_engine.h, what dealii-mpm runs with
// Backend = cuda) against the CPU step on the same grid with a node numbering that is not
// the lattice's (as deal.II's DoF numbering is not): the engine renumbers its nodes into
// lattice order on the device and must hand them back in the host's numbering.
//   - P1/V5 slump, 2 cells across (3D GIMP, 10,024 points), FLIP 0.99, pressure averaging,
//     no damping, 60 steps of fixed dt (three device re-sorts at the default interval);
//   - the host grid's nodes numbered by a random permutation of the lattice;
//   - points (download_points, upload order) and nodal mass and velocity (download_nodal,
//     host numbering) against the CPU run, within 1e-10 (reordered atomic sums only; see
//     test_gpu_cpu_agreement.cu for that bound); a permutation applied wrongly gives
//     errors of order 1;
//   - the downloaded nodal mass sums to the points' mass.
#include "../core/check.h"
#include "gpu_scenes.h"

#include <mpm/cuda/device_engine.h>

#include <algorithm>
#include <numeric>
#include <random>

using namespace mpm;
using namespace mpm_test;

int main()
{
  if (!cuda_device_present("test_gpu_device_engine"))
    return skip_code;

  HostGrid<3, double>                     lattice_grid;
  HostPoints<3, double>                   points;
  std::vector<MaterialParameters<double>> materials;
  mpm_bench::make_p1(2, lattice_grid, points, materials);

  // The same grid, nodes numbered by a permutation of the lattice.
  const int        n_nodes = lattice_grid.mass.size();
  std::vector<int> permutation(n_nodes);
  std::iota(permutation.begin(), permutation.end(), 0);
  std::mt19937 rng(5);
  std::shuffle(permutation.begin(), permutation.end(), rng);
  HostGrid<3, double> grid = lattice_grid;
  for (int l = 0; l < n_nodes; ++l)
    {
      check(lattice_grid.lattice_to_node[l] == l, "the P1 scene's grid is numbered as the lattice");
      grid.lattice_to_node[l]                = permutation[l];
      grid.fixed_components[permutation[l]] = lattice_grid.fixed_components[l];
    }

  StepSettings<3, double> s = mpm_bench::p1_settings<double>();
  s.damping                 = 0;
  s.flip_fraction           = 0.99;
  s.pressure_averaging      = true;
  const double dt           = mpm_bench::P1::cfl * mpm_bench::P1::h / mpm_bench::p1_wave_speed();
  const int    n_steps      = 60;

  HostPoints<3, double> cpu_points = points;
  CpuBackend            cpu;
  mpm::cuda::DeviceEngine<3> engine(grid.view(), materials, ShapeFunction::gimp);
  engine.upload_points(points);
  double time = 0;
  for (int step = 0; step < n_steps; ++step, time += dt)
    {
      mpm_bench::p1_gravity(s, time);
      explicit_step<3, GimpShape>(cpu, grid.view(), cpu_points.view(), materials.data(), s, dt);
      engine.step(s, dt);
    }

  HostPoints<3, double> gpu_points;
  engine.download_points(gpu_points);
  HostGrid<3, double> gpu_grid = grid; // same numbering, nodal arrays overwritten
  engine.download_nodal(gpu_grid.view());

  double dx = 0, dv = 0, v_max = 0;
  for (int i = 0; i < points.size(); ++i)
    for (int d = 0; d < 3; ++d)
      {
        dx    = std::max(dx, std::abs(gpu_points.position[d][i] - cpu_points.position[d][i]) / mpm_bench::P1::h);
        dv    = std::max(dv, std::abs(gpu_points.velocity[d][i] - cpu_points.velocity[d][i]));
        v_max = std::max(v_max, std::abs(cpu_points.velocity[d][i]));
      }
  double dm = 0, m_max = 0, dvn = 0, m_sum = 0, m_points = 0;
  for (int n = 0; n < n_nodes; ++n)
    {
      dm    = std::max(dm, std::abs(gpu_grid.mass[n] - grid.mass[n]));
      m_max = std::max(m_max, grid.mass[n]);
      m_sum += gpu_grid.mass[n];
      for (int d = 0; d < 3; ++d)
        dvn = std::max(dvn, std::abs(gpu_grid.velocity[d][n] - grid.velocity[d][n]));
    }
  for (int i = 0; i < points.size(); ++i)
    m_points += points.mass[i];
  std::printf("test_gpu_device_engine: %d points, %d nodes, %d steps | points: x/h %.1e, v %.1e (max |v| %.2e) | "
              "nodes: mass %.1e (max %.2e), v %.1e | sum of nodal mass - points' mass %.1e\n",
              points.size(), n_nodes, n_steps, dx, dv / v_max, v_max, dm / m_max, m_max, dvn / v_max,
              std::abs(m_sum - m_points) / m_points);
  check(v_max > 1e-4, "the points move");
  check_below(dx, 1e-10, "positions: DeviceEngine vs CPU (x/h)");
  check_below(dv / v_max, 1e-10, "velocities: DeviceEngine vs CPU (of max |v|)");
  check_below(dm / m_max, 1e-10, "nodal mass in the host's numbering: DeviceEngine vs CPU");
  check_below(dvn / v_max, 1e-10, "nodal velocity in the host's numbering: DeviceEngine vs CPU");
  check_below(std::abs(m_sum - m_points) / m_points, 1e-12, "downloaded nodal mass sums to the points' mass");
  return finish("test_gpu_device_engine");
}
