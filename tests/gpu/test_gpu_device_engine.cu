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
//   - the downloaded nodal mass sums to the points' mass;
//   - CPDI2q in 2D (its corners in state variables, which the engine uploads, sorts with the
//     points and downloads): a spinning elastic block, 150 steps, points and corners against the
//     CPU within 1e-10;
//   - steps queued behind each other (queue_step / collect_step, Backend/Queue steps): the
//     same P1 steps with the adaptive time step landing on output times and on the end
//     time, one engine stepped as before (the host's time step from each step's speed), one
//     queued (the device's time step from the last step's speed, collected one step
//     behind): each queued step's time step equals the host's rule on the collected speeds
//     to the bit, the steps and their time steps match the stepped engine's (1e-12), and
//     the points within 1e-10 as above; a third queued step before a collect is refused, and
//     so is the device's speed where no step is queued before.
//     Twice: with P1's gravity ramp (no step replayed as a CUDA graph) and with full gravity
//     and pressure averaging (the steps between the sorts replayed as graphs);
//   - the float engine (DeviceEngine<3, float>, Backend/Precision = float) on the same P1 steps:
//     against the CPU's float step within 1e-5 h in position and 1e-4 of max |v| (float's
//     round-off, 6e-8, summed in another order), against the double engine within 1e-4 h and
//     1e-3 (and not equal to it: the step did run in float); its totals summed in double, the
//     mass within 1e-7 of the double points' (each mass rounded once);
//   - an output's download while the steps go on (begin_download_points), in double and in
//     float: the points as at its beginning after 45 more steps were queued behind it (against
//     a second engine, as above), and a second download before the first is refused.
#include "../core/check.h"
#include "gpu_scenes.h"

#include <mpm/core/precision.h>
#include <mpm/cuda/device_engine.h>

#include <algorithm>
#include <numeric>
#include <random>
#include <string>
#include <type_traits>
#include <utility>

using namespace mpm;
using namespace mpm_test;

// CPDI2q through the engine: a block spun at 2 rad/s on a 16 x 16 grid, no gravity.
void cpdi2q_through_engine()
{
  HostGrid<2, double> grid;
  const double        lower[2] = {0, 0}, block_lo[2] = {0.25, 0.25}, block_hi[2] = {0.75, 0.75};
  const int           cells[2] = {16, 16};
  grid.make_dense(lower, 1.0 / 16, cells);
  HostPoints<2, double> points;
  add_points(points, grid, block_lo, block_hi, BodyDescription<2, double>{2, 1000, {0, 0}, 0},
             [](const double *) { return true; });
  points.set_n_state_variables(8);
  for (int i = 0; i < points.size(); ++i)
    {
      points.velocity[0][i] = -2 * (points.position[1][i] - 0.5);
      points.velocity[1][i] = 2 * (points.position[0][i] - 0.5);
    }
  std::vector<MaterialParameters<double>> materials(1);
  materials[0].model                  = MaterialModel::linear_elastic;
  materials[0].elastic.youngs_modulus = 1e6;
  materials[0].elastic.poissons_ratio = 0.3;
  StepSettings<2, double> s;
  s.gravity[0] = s.gravity[1] = 0;
  s.damping                   = 0;
  s.flip_fraction             = 0.99;
  s.corner_state_variable     = 0;
  s.mass_tolerance            = 1e-12 * points.mass[0];
  const double dt             = 0.3 * grid.h / std::sqrt(1e6 * 1.35 / 1000);

  HostPoints<2, double>      cpu_points = points;
  CpuBackend                 cpu;
  mpm::cuda::DeviceEngine<2> engine(grid.view(), materials, ShapeFunction::cpdi2q);
  engine.upload_points(points);
  for (int step = 0; step < 150; ++step)
    {
      explicit_step<2, Cpdi2qShape>(cpu, grid.view(), cpu_points.view(), materials.data(), s, dt);
      engine.step(s, dt);
    }
  HostPoints<2, double> gpu_points;
  engine.download_points(gpu_points);
  double dx = 0, dq = 0, q_max = 0;
  for (int i = 0; i < points.size(); ++i)
    {
      for (int d = 0; d < 2; ++d)
        dx = std::max(dx, std::abs(gpu_points.position[d][i] - cpu_points.position[d][i]) / grid.h);
      for (int k = 0; k < 8; ++k)
        {
          dq    = std::max(dq, gpu_points.n_state_variables() < 8 ?
                                 INFINITY :
                                 std::abs(gpu_points.state_variables[k][i] - cpu_points.state_variables[k][i]) / grid.h);
          q_max = std::max(q_max, std::abs(cpu_points.state_variables[k][i]) / grid.h);
        }
    }
  std::printf("test_gpu_device_engine: CPDI2q spinning block, %d points, 150 steps | x/h %.1e, corners/h %.1e "
              "(largest corner offset from its rectangle %.2e h)\n",
              points.size(), dx, dq, q_max);
  check(q_max > 1e-3, "CPDI2q: the corners have moved off their rectangles");
  check_below(dx, 1e-10, "CPDI2q: positions, DeviceEngine vs CPU (x/h)");
  check_below(dq, 1e-10, "CPDI2q: corners, DeviceEngine vs CPU (/h)");
}

// Queued steps against stepped ones (the header's list).
// ramping: P1's gravity ramp (the settings change every step: no graph); otherwise full
// gravity and pressure averaging (the same launches every step: replayed as CUDA graphs).
void queued_steps(HostGrid<3, double> grid, const HostPoints<3, double> &points,
                  const std::vector<MaterialParameters<double>> &materials, StepSettings<3, double> s,
                  const bool ramping)
{
  const char *label = ramping ? "queued (gravity ramp)" : "queued (graphs)";
  auto gravity = [&](const double time) {
    if (ramping)
      mpm_bench::p1_gravity(s, time);
    else
      mpm_bench::p1_gravity(s, 1e300);
  };
  s.pressure_averaging = !ramping;
  const double dt0 = mpm_bench::P1::cfl * mpm_bench::P1::h / mpm_bench::p1_wave_speed();
  TimeStepRule rule;
  rule.cfl_times_h      = mpm_bench::P1::cfl * mpm_bench::P1::h;
  rule.wave_speed       = mpm_bench::p1_wave_speed();
  rule.end_time         = 40.3 * dt0;
  rule.lands_on_outputs = true;
  rule.shortest_landing = 1e-12 * rule.end_time;
  const double interval = 2.5 * dt0; // a landing every two or three steps
  auto next_output_after = [&](const double time, double next_output) {
    while (time >= next_output * (1 - 1e-12))
      next_output += interval;
    return next_output;
  };

  mpm::cuda::DeviceEngine<3> stepped(grid.view(), materials, ShapeFunction::gimp);
  stepped.upload_points(points);

  std::vector<double> stepped_dt, queued_dt;
  {
    double time = 0, next_output = interval, speed = 0;
    while (time < rule.end_time * (1 - 1e-12))
      {
        const double dt = next_time_step(rule, speed, time, next_output);
        gravity(time);
        speed = finite_or_infinite_speed(stepped.step(s, dt).max_speed);
        stepped_dt.push_back(dt);
        time += dt;
        next_output = next_output_after(time, next_output);
      }
  }
  mpm::cuda::DeviceEngine<3> queued(grid.view(), materials, ShapeFunction::gimp);
  queued.upload_points(points);
  int    mismatched = 0;
  double time = 0, next_output = interval, speed = 0, last_dt = 0;
  int landings = 0;
  while (time < rule.end_time * (1 - 1e-12))
    {
      gravity(time);
      queued.queue_step(s, rule, time, next_output, queued_dt.empty(), speed);
      if (!queued_dt.empty())
        {
          const QueuedStep q = queued.collect_step();
          mismatched += q.dt != last_dt;
          speed = finite_or_infinite_speed(q.reduction.max_speed);
        }
      last_dt = next_time_step(rule, speed, time, next_output);
      landings += last_dt < 0.99 * rule.cfl_times_h / (rule.wave_speed + speed);
      queued_dt.push_back(last_dt);
      time += last_dt;
      next_output = next_output_after(time, next_output);
    }
  mismatched += queued.collect_step().dt != last_dt;
  check(queued.queued_steps() == 0, "every queued step collected");

  double ddt = 0;
  for (size_t k = 0; k < std::min(stepped_dt.size(), queued_dt.size()); ++k)
    ddt = std::max(ddt, std::abs(queued_dt[k] - stepped_dt[k]) / dt0);
  HostPoints<3, double> a, b;
  stepped.download_points(a);
  queued.download_points(b);
  double dx = 0, dv = 0, v_max = 0;
  for (int i = 0; i < points.size(); ++i)
    for (int d = 0; d < 3; ++d)
      {
        dx    = std::max(dx, std::abs(a.position[d][i] - b.position[d][i]) / mpm_bench::P1::h);
        dv    = std::max(dv, std::abs(a.velocity[d][i] - b.velocity[d][i]));
        v_max = std::max(v_max, std::abs(a.velocity[d][i]));
      }
  const long replays = queued.graph_replays(), captures = queued.graph_captures();
  std::printf("test_gpu_device_engine: %s, %zu steps (stepped: %zu), %d cut to land on an output or the end, "
              "%ld replayed as a CUDA graph (%ld captures) | device's dt against the host's rule: %d differ | dt "
              "against the stepped engine's %.1e dt0 | points against it: x/h %.1e, v %.1e (max |v| %.2e)\n",
              label, queued_dt.size(), stepped_dt.size(), landings, replays, captures, mismatched, ddt, dx,
              dv / v_max, v_max);
  const std::string l = std::string(label) + ": ";
  check(landings >= 10, (l + "steps cut to land on output times").c_str());
  check(mismatched == 0, (l + "the device's time step equals the host's rule to the bit").c_str());
  check(queued_dt.size() == stepped_dt.size(), (l + "as many steps as stepped").c_str());
  check_below(ddt, 1e-12, (l + "time steps against the stepped engine's (of dt0)").c_str());
  check(v_max > 1e-4, (l + "the points move").c_str());
  check_below(dx, 1e-10, (l + "positions against the stepped engine (x/h)").c_str());
  check_below(dv / v_max, 1e-10, (l + "velocities against the stepped engine (of max |v|)").c_str());
  if (ramping)
    check(replays == 0, (l + "no graph where the settings change every step").c_str());
  else // sorts every 20 steps: all but the sorts, the two steps after the first two and the captures
    check(replays >= 35 && captures <= 4, (l + "the steps between the sorts replayed as graphs").c_str());

  // A third queued step before a collect is refused (the host's two pinned slots).
  bool refused = false;
  queued.queue_step(s, rule, 0, interval, true, 0);
  queued.queue_step(s, rule, 0, interval, false, 0);
  try
    {
      queued.queue_step(s, rule, 0, interval, false, 0);
    }
  catch (const std::logic_error &)
    {
      refused = true;
    }
  queued.collect_step();
  queued.collect_step();
  check(refused, "queue_step refuses a third uncollected step");
  // With every step collected, the device's last record is no step's before: refused too.
  bool stale_refused = false;
  try
    {
      queued.queue_step(s, rule, 0, interval, false, 0);
    }
  catch (const std::logic_error &)
    {
      stale_refused = true;
    }
  check(stale_refused && queued.queued_steps() == 0, "queue_step refuses the device's speed with no step queued");
}

// An output's download that does not hold up the steps (begin_download_points): begun after
// `n_steps` steps with the pressure averaging still pending, then steps queued at once and
// replayed as graphs, and only then waited for. It must hold the points as they were at its
// beginning: against a second engine stepped as far and downloaded the waiting way
// (download_points), within the agreement of two engines (reordered atomic sums), and far
// from the points after the later steps. A second download before the first is finished is
// refused.
template <typename Real>
void download_while_stepping(HostGrid<3, double> grid, const HostPoints<3, double> &points,
                             const std::vector<MaterialParameters<double>> &materials, StepSettings<3, double> s,
                             const double dt, const int n_steps, const double tolerance)
{
  const char *label = std::is_same<Real, double>::value ? "download while stepping" : "download while stepping (float)";
  mpm::cuda::DeviceEngine<3, Real> engine(grid.view(), materials, ShapeFunction::gimp);
  mpm::cuda::DeviceEngine<3, Real> reference(grid.view(), materials, ShapeFunction::gimp);
  engine.upload_points(points);
  reference.upload_points(points);
  double time = 0;
  for (int step = 0; step < n_steps; ++step, time += dt)
    {
      mpm_bench::p1_gravity(s, time);
      engine.step(s, dt);
      reference.step(s, dt);
    }
  HostPoints<3, double> begun, refused_into;
  auto                  arrive  = engine.begin_download_points(begun);
  bool                  refused = false;
  try
    {
      engine.begin_download_points(refused_into);
    }
  catch (const std::logic_error &)
    {
      refused = true;
    }

  mpm_bench::p1_gravity(s, 1e300); // the same launches every step: graphs
  TimeStepRule rule;
  rule.cfl_times_h = mpm_bench::P1::cfl * mpm_bench::P1::h;
  rule.wave_speed  = mpm_bench::p1_wave_speed();
  rule.end_time    = 1e300;
  const int n_later = 45;
  for (int k = 0; k < n_later; ++k)
    {
      engine.queue_step(s, rule, time, 1e300, k == 0, 0);
      if (k > 0)
        time += engine.collect_step().dt;
    }
  time += engine.collect_step().dt;
  arrive();

  HostPoints<3, double> expected, later;
  reference.download_points(expected);
  engine.download_points(later);
  auto largest_difference = [&](const HostPoints<3, double> &a, const HostPoints<3, double> &b) {
    double dx = 0, dsigma = 0, sigma_max = 0;
    for (int i = 0; i < points.size(); ++i)
      {
        for (int d = 0; d < 3; ++d)
          dx = std::max(dx, std::abs(a.position[d][i] - b.position[d][i]) / mpm_bench::P1::h);
        for (int c = 0; c < n_voigt; ++c)
          {
            dsigma    = std::max(dsigma, std::abs(a.stress[c][i] - b.stress[c][i]));
            sigma_max = std::max(sigma_max, std::abs(b.stress[c][i]));
          }
      }
    return std::make_pair(dx, dsigma / sigma_max);
  };
  const auto [dx, dsigma]             = largest_difference(begun, expected);
  const auto [dx_later, dsigma_later] = largest_difference(begun, later);
  std::printf("test_gpu_device_engine: %s, begun after %d steps, waited for after %d more | against a second "
              "engine's download: x/h %.1e, stress %.1e | against the points after them: x/h %.1e\n",
              label, n_steps, n_later, dx, dsigma, dx_later);
  const std::string l = std::string(label) + ": ";
  check(refused, (l + "a second download before the first is finished is refused").c_str());
  check(begun.size() == points.size(), (l + "every point downloaded").c_str());
  check_below(dx, tolerance, (l + "positions as at the download's beginning (x/h)").c_str());
  check_below(dsigma, 100 * tolerance, (l + "stresses as at the download's beginning (of max |sigma|)").c_str());
  check(dx_later > 1e3 * tolerance, (l + "the later steps moved the points (and did not reach the download)").c_str());
}

// The float engine on P1's steps, against the CPU's float step and the double engine.
void float_engine(HostGrid<3, double> grid, const HostPoints<3, double> &points,
                  const std::vector<MaterialParameters<double>> &materials, StepSettings<3, double> s, const double dt,
                  const int n_steps)
{
  HostGrid<3, float>                     cpu_grid = converted<float>(grid);
  HostPoints<3, float>                   cpu_points;
  convert_points<float>(points, cpu_points);
  const std::vector<MaterialParameters<float>> cpu_materials = converted<float>(materials);
  CpuBackend                                    cpu;
  mpm::cuda::DeviceEngine<3, float>             engine(grid.view(), materials, ShapeFunction::gimp);
  mpm::cuda::DeviceEngine<3, double>            wide(grid.view(), materials, ShapeFunction::gimp);
  engine.upload_points(points);
  wide.upload_points(points);
  double time = 0;
  for (int step = 0; step < n_steps; ++step, time += dt)
    {
      mpm_bench::p1_gravity(s, time);
      explicit_step<3, GimpShape>(cpu, cpu_grid.view(), cpu_points.view(), cpu_materials.data(),
                                  converted<float>(s), static_cast<float>(dt));
      engine.step(s, dt);
      wide.step(s, dt);
    }
  HostPoints<3, double> gpu_points, double_points;
  engine.download_points(gpu_points);
  wide.download_points(double_points);
  double dx = 0, dv = 0, dx_double = 0, dv_double = 0, v_max = 0;
  for (int i = 0; i < points.size(); ++i)
    for (int d = 0; d < 3; ++d)
      {
        const double h = mpm_bench::P1::h;
        dx             = std::max(dx, std::abs(gpu_points.position[d][i] - cpu_points.position[d][i]) / h);
        dv             = std::max(dv, std::abs(gpu_points.velocity[d][i] - cpu_points.velocity[d][i]));
        dx_double = std::max(dx_double, std::abs(gpu_points.position[d][i] - double_points.position[d][i]) / h);
        dv_double = std::max(dv_double, std::abs(gpu_points.velocity[d][i] - double_points.velocity[d][i]));
        v_max     = std::max(v_max, std::abs(double_points.velocity[d][i]));
      }
  double m_points = 0;
  for (int i = 0; i < points.size(); ++i)
    m_points += points.mass[i];
  const PointTotals<3, double> totals = engine.totals();
  std::printf("test_gpu_device_engine: float engine, %d steps | against the CPU in float: x/h %.1e, v %.1e | against "
              "the double engine: x/h %.1e, v %.1e (max |v| %.2e) | mass %.1e of the double points'\n",
              n_steps, dx, dv / v_max, dx_double, dv_double / v_max, v_max,
              std::abs(totals.mass - m_points) / m_points);
  check(v_max > 1e-4, "float: the points move");
  check_below(dx, 1e-5, "float: positions, DeviceEngine vs CPU in float (x/h)");
  check_below(dv / v_max, 1e-4, "float: velocities, DeviceEngine vs CPU in float (of max |v|)");
  check_below(dx_double, 1e-4, "float: positions, against the double engine (x/h)");
  check_below(dv_double / v_max, 1e-3, "float: velocities, against the double engine (of max |v|)");
  check(dv_double > 0, "float: the float engine's velocities differ from the double engine's (it ran in float)");
  check(totals.n_points == points.size(), "float: totals count every point");
  check_below(std::abs(totals.mass - m_points) / m_points, 1e-7, "float: total mass against the double points'");
}

int main()
{
  if (!cuda_device_present("test_gpu_device_engine"))
    return skip_code;
  cpdi2q_through_engine();

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

  s.gravity[0] = s.gravity[1] = s.gravity[2] = 0; // p1_gravity sets them again from the start
  queued_steps(grid, points, materials, s, true);
  queued_steps(grid, points, materials, s, false);
  float_engine(grid, points, materials, s, dt, n_steps);
  download_while_stepping<double>(grid, points, materials, s, dt, 30, 1e-10);
  download_while_stepping<float>(grid, points, materials, s, dt, 30, 1e-5);
  return finish("test_gpu_device_engine");
}
