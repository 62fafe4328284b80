// CPU against GPU per point: the tolerance and the CPU's own reordering spread that
// test_gpu_cpu_agreement.cu's header derives, shared by the agreement tests.
#pragma once

#include "../core/check.h"
#include "gpu_targets.h"

#include <algorithm>
#include <cstdio>
#include <string>
#include <vector>

namespace mpm_test
{
  constexpr double tolerance = 1e-10;

  // Random orders, besides the reversed one, over which the CPU's reordering spread is taken.
  constexpr unsigned n_random_orders = 4;

  // The CPU's own sensitivity to the order of its sums: run(out, &start) runs the scene on
  // the CPU from the points of initial listed in another order (reversed, and
  // n_random_orders reproducible random ones); each result, put back in the original order,
  // is compared with the CPU run cpu. Returns the largest difference per field.
  template <int dim, typename Run>
  Difference cpu_reordering_spread(const mpm::HostPoints<dim, double> &initial, const mpm::HostPoints<dim, double> &cpu,
                                   const double h, Run &&run)
  {
    std::vector<std::vector<int>> orders{reversed_order(initial.size())};
    for (unsigned seed = 1; seed <= n_random_orders; ++seed)
      orders.push_back(random_order(initial.size(), seed));
    Difference spread;
    for (const std::vector<int> &order : orders)
      {
        mpm::HostPoints<dim, double>       out;
        const mpm::HostPoints<dim, double> start = permuted(initial, order);
        run(out, &start);
        const Difference d = compare_points(cpu, permuted(out, inverse_order(order)), h);
        spread.position    = std::max(spread.position, d.position);
        spread.velocity    = std::max(spread.velocity, d.velocity);
        spread.stress      = std::max(spread.stress, d.stress);
      }
    return spread;
  }

  template <int dim>
  void report(const char *scene, const Difference &gpu, const Difference &reordered, const long steps,
              const bool damped)
  {
    std::printf("%-34s %6ld steps | GPU-CPU: x/h %.1e v %.1e sigma %.1e | CPU reordered: x/h %.1e v %.1e sigma %.1e\n",
                scene, steps, gpu.position, gpu.velocity, gpu.stress, reordered.position, reordered.velocity,
                reordered.stress);
    const double      limit = damped ? std::max(tolerance, 100 * reordered.worst()) : tolerance;
    const std::string what  = std::string(scene) + (damped ? ": GPU vs CPU within max(1e-10, 100x CPU reordering)" :
                                                             ": GPU vs CPU per point within 1e-10");
    check_below(gpu.worst(), limit, what.c_str());
    check(gpu.removed_mismatch == 0, (std::string(scene) + ": same points removed").c_str());
  }

  // Fraction of the points with accumulated plastic strain (a scene that is to exercise the
  // plastic return checks it).
  template <int dim>
  double plastic_fraction(const mpm::HostPoints<dim, double> &p)
  {
    int yielded = 0;
    for (int i = 0; i < p.size(); ++i)
      yielded += p.plastic_strain[i] > 0;
    return double(yielded) / p.size();
  }
} // namespace mpm_test
