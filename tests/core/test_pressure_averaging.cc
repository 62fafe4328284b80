// Cell pressure averaging (step.h, stages::average_cell_pressure) in 2D and 3D on
// random points with random stresses:
//  - after averaging, all points of a cell share the volume-weighted mean pressure
//    sum V_p p_p / sum V_p of that cell before averaging;
//  - the deviatoric stress of every point is untouched;
//  - the total pressure-volume sum_p V_p p_p is conserved, per cell and overall;
//  - a cell holding one point, removed points and a second averaging change nothing;
//  - the full step with averaging on leaves equal pressures per cell (MUSL, USL, USF);
//  - the deferred averaging (explicit_step's averaging_pending: applied by the next
//    step's P2G or by finish_pressure_averaging) gives the same points as the one done
//    at the end of each step, to the last bit (the same operations on the same values);
//    also where it is finished between two steps (as the GPU's output does when it reads
//    the points) and the run goes on, in double and in float, with the cell sums per
//    lattice cell and at each cell's lowest node (nodes near the material).
#include "check.h"
#include "scene_helpers.h"

#include <mpm/core/backend/cpu_backend.h>
#include <mpm/core/precision.h>
#include <mpm/core/step.h>

#include <algorithm>
#include <cstdio>
#include <map>
#include <random>
#include <vector>

using namespace mpm;
using mpm_test::check;
using mpm_test::check_below;

namespace
{
  template <int dim>
  double mean_stress(const HostPoints<dim, double> &p, const int i)
  {
    return (p.stress[0][i] + p.stress[1][i] + p.stress[2][i]) / 3;
  }

  template <int dim>
  std::map<int, std::pair<double, double>> cell_sums(HostGrid<dim, double> &g, const HostPoints<dim, double> &p)
  {
    // cell -> (sum V, sum V p)
    std::map<int, std::pair<double, double>> sums;
    const GridView<dim, double> v = g.view();
    for (int i = 0; i < p.size(); ++i)
      {
        if (p.material[i] < 0)
          continue;
        double x[dim];
        for (int d = 0; d < dim; ++d)
          x[d] = p.position[d][i];
        auto &s = sums[v.lattice_cell(x)];
        s.first += p.volume[i];
        s.second += p.volume[i] * mean_stress(p, i);
      }
    return sums;
  }

  template <int dim>
  void test_stage(const int n_points)
  {
    std::mt19937           rng(42 + dim);
    HostGrid<dim, double>  g;
    const double           lower[3] = {0, -1, 0.5};
    const int              cells[3] = {12, 10, 8};
    g.make_dense(lower, 0.25, cells);
    HostPoints<dim, double> p;
    mpm_test::random_points<dim>(p, g, n_points, rng);
    // A lone point in a corner cell, and two removed points (their stress must stay).
    for (int d = 0; d < dim; ++d)
      p.position[d][0] = g.origin[d] + 0.5 * g.h;
    p.material[1] = p.material[2] = -1;
    const HostPoints<dim, double> before = p;
    const auto                    sums   = cell_sums(g, p);

    CpuBackend backend;
    stages::average_cell_pressure(backend, g.view(), p.view());

    const GridView<dim, double> v = g.view();
    double max_pressure_error = 0, max_deviator_change = 0, total_before = 0, total_after = 0, scale = 0;
    int    lone_cells = 0;
    for (int i = 0; i < p.size(); ++i)
      {
        if (p.material[i] < 0)
          {
            for (int c = 0; c < n_voigt; ++c)
              check(p.stress[c][i] == before.stress[c][i], "removed point's stress untouched");
            continue;
          }
        double x[dim];
        for (int d = 0; d < dim; ++d)
          x[d] = p.position[d][i];
        const auto  &s        = sums.at(v.lattice_cell(x));
        const double expected = s.second / s.first;
        const double m_before = mean_stress(before, i), m_after = mean_stress(p, i);
        scale                 = std::max(scale, std::fabs(m_before));
        max_pressure_error    = std::max(max_pressure_error, std::fabs(m_after - expected));
        for (int c = 0; c < n_voigt; ++c)
          {
            const double dev_before = before.stress[c][i] - (c < 3 ? m_before : 0);
            const double dev_after  = p.stress[c][i] - (c < 3 ? m_after : 0);
            max_deviator_change     = std::max(max_deviator_change, std::fabs(dev_after - dev_before));
          }
        total_before += before.volume[i] * m_before;
        total_after += p.volume[i] * m_after;
        if (std::fabs(s.first - p.volume[i]) < 1e-15 && ++lone_cells)
          check(std::fabs(m_after - m_before) <= 1e-13 * scale, "a lone point keeps its pressure");
      }
    std::printf("%dD, %d points in %zu cells (%d with one point): max |p - p_cell| %.2e, max deviator change "
                "%.2e, pressure-volume before %.15e after %.15e\n",
                dim, n_points, sums.size(), lone_cells, max_pressure_error, max_deviator_change, total_before,
                total_after);
    check(lone_cells >= 1, "the corner cell holds one point");
    check_below(max_pressure_error, 1e-13 * scale, "every point has the volume-weighted cell pressure");
    check_below(max_deviator_change, 1e-13 * scale, "deviatoric stress untouched");
    check_below(std::fabs(total_after - total_before), 1e-13 * std::fabs(total_before) + 1e-300,
                "total pressure-volume conserved");
    // Per cell too.
    const auto sums_after = cell_sums(g, p);
    double     worst      = 0;
    for (const auto &[cell, s] : sums)
      worst = std::max(worst, std::fabs(sums_after.at(cell).second - s.second) / (s.first * scale));
    check_below(worst, 1e-13, "pressure-volume conserved in every cell");

    // Averaging is a projection: applying it again changes nothing.
    const HostPoints<dim, double> once = p;
    stages::average_cell_pressure(backend, g.view(), p.view());
    double change = 0;
    for (int i = 0; i < p.size(); ++i)
      for (int c = 0; c < n_voigt; ++c)
        change = std::max(change, std::fabs(p.stress[c][i] - once.stress[c][i]));
    check_below(change, 1e-13 * scale, "averaging twice = averaging once");
  }

  // The scene of the step tests: a dense grid of 8^dim cells of 0.125 and 400 random points in
  // its middle (random stresses), drawn from `seed`.
  template <int dim>
  void random_scene(const unsigned int seed, HostGrid<dim, double> &g, HostPoints<dim, double> &p)
  {
    std::mt19937 rng(seed);
    const double lower[3] = {0, 0, 0};
    const int    cells[3] = {8, 8, 8};
    g.make_dense(lower, 0.125, cells);
    mpm_test::random_points<dim>(p, g, 400, rng);
  }

  // The full step with averaging on: after each step the points of a cell share one pressure.
  template <int dim>
  void test_in_step(const UpdateScheme scheme)
  {
    HostGrid<dim, double>   g;
    HostPoints<dim, double> p;
    random_scene<dim>(7, g, p);
    auto s               = mpm_test::quiet_settings<dim>(scheme);
    s.pressure_averaging = true;
    std::vector<MaterialParameters<double>> materials = {mpm_test::elastic(1e4, 0.3)};
    CpuBackend                              backend;
    double                                  worst = 0, scale = 0;
    for (int step = 0; step < 3; ++step)
      {
        explicit_step<dim, GimpShape>(backend, g.view(), p.view(), materials.data(), s, 1e-4);
        std::map<int, std::pair<double, double>> range; // cell -> (min p, max p)
        const GridView<dim, double>              v = g.view();
        for (int i = 0; i < p.size(); ++i)
          {
            double x[dim];
            for (int d = 0; d < dim; ++d)
              x[d] = p.position[d][i];
            const double m  = mean_stress(p, i);
            scale           = std::max(scale, std::fabs(m));
            auto it         = range.find(v.lattice_cell(x));
            if (it == range.end())
              range[v.lattice_cell(x)] = {m, m};
            else
              it->second = {std::min(it->second.first, m), std::max(it->second.second, m)};
          }
        for (const auto &[cell, r] : range)
          worst = std::max(worst, r.second - r.first);
      }
    std::printf("%dD step (scheme %d): max pressure spread in a cell %.2e (pressure scale %.2e)\n", dim,
                int(scheme), worst, scale);
    check_below(worst, 1e-12 * scale, "one pressure per cell after a step with averaging");
  }
  // Deferred against immediate averaging, 5 steps with a finish at the end.
  template <int dim>
  void test_deferred(const UpdateScheme scheme)
  {
    HostGrid<dim, double>   g_now;
    HostPoints<dim, double> now;
    random_scene<dim>(11, g_now, now);
    HostGrid<dim, double>   g_later = g_now;
    HostPoints<dim, double> later   = now;
    auto s                        = mpm_test::quiet_settings<dim>(scheme);
    s.pressure_averaging          = true;
    std::vector<MaterialParameters<double>> materials = {mpm_test::elastic(1e4, 0.3)};
    CpuBackend                              backend;
    bool                                    pending = false;
    for (int step = 0; step < 5; ++step)
      {
        explicit_step<dim, GimpShape>(backend, g_now.view(), now.view(), materials.data(), s, 1e-4);
        explicit_step<dim, GimpShape>(backend, g_later.view(), later.view(), materials.data(), s, 1e-4,
                                      NoGridExchange(), &pending);
      }
    check(pending == (scheme != UpdateScheme::usf), "MUSL and USL leave the averaging pending, USF does not");
    double before = 0;
    for (int i = 0; i < now.size(); ++i)
      for (int c = 0; c < n_voigt; ++c)
        before = std::max(before, std::fabs(now.stress[c][i] - later.stress[c][i]));
    if (pending)
      stages::finish_pressure_averaging(backend, g_later.view(), later.view());
    double after = 0;
    for (int i = 0; i < now.size(); ++i)
      {
        for (int c = 0; c < n_voigt; ++c)
          after = std::max(after, std::fabs(now.stress[c][i] - later.stress[c][i]));
        for (int d = 0; d < dim; ++d)
          after = std::max({after, std::fabs(now.position[d][i] - later.position[d][i]),
                            std::fabs(now.velocity[d][i] - later.velocity[d][i])});
      }
    std::printf("%dD deferred averaging (scheme %d): stress difference %.2e before the finish, %.2e after\n", dim,
                int(scheme), before, after);
    if (pending)
      check(before > 0, "the deferred averaging is still pending before the finish");
    check(after == 0, "deferred averaging = averaging at the end of each step, bit for bit");
  }

  // A finish between steps (an output reading the points on the GPU) and then more deferred
  // steps: the same points as averaging at the end of every step, bit for bit.
  template <int dim, typename Real>
  void test_finished_between_steps(const UpdateScheme scheme, const bool sums_at_nodes)
  {
    HostGrid<dim, double>   g;
    HostPoints<dim, double> start;
    random_scene<dim>(13, g, start);
    HostGrid<dim, Real> g_now = converted<Real>(g), g_between = converted<Real>(g);
    if (sums_at_nodes) // one entry per node, a cell's at its lowest vertex
      for (HostGrid<dim, Real> *grid : {&g_now, &g_between})
        {
          grid->cell_volume.assign(grid->mass.size(), Real(0));
          grid->cell_pressure_volume.assign(grid->mass.size(), Real(0));
        }
    auto view = [sums_at_nodes](HostGrid<dim, Real> &grid) {
      GridView<dim, Real> v = grid.view();
      v.cell_sums_at_nodes  = sums_at_nodes;
      return v;
    };
    HostPoints<dim, Real> now, between;
    convert_points<Real>(start, now);
    convert_points<Real>(start, between);
    auto s               = converted<Real>(mpm_test::quiet_settings<dim>(scheme));
    s.pressure_averaging = true;
    const std::vector<MaterialParameters<Real>> materials = {converted<Real>(mpm_test::elastic(1e4, 0.3))};
    CpuBackend                                  backend;
    bool                                        pending = false;
    for (int step = 0; step < 6; ++step)
      {
        explicit_step<dim, GimpShape>(backend, view(g_now), now.view(), materials.data(), s, Real(1e-4));
        explicit_step<dim, GimpShape>(backend, view(g_between), between.view(), materials.data(), s, Real(1e-4),
                                      NoGridExchange(), &pending);
        if ((step == 1 || step == 5) && pending) // an output after steps 2 and 6
          {
            stages::finish_pressure_averaging(backend, view(g_between), between.view());
            pending = false;
          }
      }
    double difference = 0, scale = 0;
    for (int i = 0; i < now.size(); ++i)
      {
        for (int c = 0; c < n_voigt; ++c)
          {
            difference = std::max(difference, double(std::fabs(now.stress[c][i] - between.stress[c][i])));
            scale      = std::max(scale, double(std::fabs(now.stress[c][i])));
          }
        for (int d = 0; d < dim; ++d)
          difference = std::max({difference, double(std::fabs(now.position[d][i] - between.position[d][i])),
                                 double(std::fabs(now.velocity[d][i] - between.velocity[d][i]))});
      }
    std::printf("%dD %s, cell sums %s (scheme %d): finished between steps, largest difference %.2e (stress "
                "scale %.2e)\n",
                dim, sizeof(Real) == 4 ? "float" : "double", sums_at_nodes ? "at nodes" : "per cell", int(scheme),
                difference, scale);
    check(scale > 0, "the points carry stress");
    check(difference == 0, "a deferred averaging finished between steps = averaging at the end of each step");
  }
} // namespace

int main()
{
  test_stage<2>(500);
  test_stage<3>(2000);
  for (const UpdateScheme scheme : {UpdateScheme::musl, UpdateScheme::usl, UpdateScheme::usf})
    {
      test_in_step<2>(scheme);
      test_in_step<3>(scheme);
      test_deferred<2>(scheme);
      test_deferred<3>(scheme);
      for (const bool at_nodes : {false, true})
        {
          test_finished_between_steps<2, double>(scheme, at_nodes);
          test_finished_between_steps<3, double>(scheme, at_nodes);
          test_finished_between_steps<2, float>(scheme, at_nodes);
          test_finished_between_steps<3, float>(scheme, at_nodes);
        }
    }
  return mpm_test::finish("test_pressure_averaging");
}
