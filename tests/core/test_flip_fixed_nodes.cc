// StepSettings::flip_fixed_velocity_change (Solver/FLIP at fixed nodes), one MUSL step, exact.
//
// A block translates at v0 with zero stress and no gravity; its lowest row of points touches a
// no-slip base (uGIMP, h/4 half-lengths, 2 x 2 points per cell). Every node with mass then has
// the velocity v0 before the update, and no free node accelerates. With the FLIP fraction a:
//   no change:       v_p = a v0 + (1 - a) (1 - s_p) v0
//   velocity change: v_p = (1 - s_p) v0          (the base's change -v0 passed to FLIP as well)
// where s_p = sum of N_ip over the base's nodes: the GIMP weight of the node row at y = 0, which
// is 3/4 for points at y = h/4, 1/4 at y = 3h/4 and 0 from y = 5h/4 up (the x weights sum to 1).
#include "check.h"
#include "scene_helpers.h"

#include <mpm/core/point_generation.h>

#include <cmath>
#include <cstdio>
#include <vector>

using namespace mpm;
using mpm_test::check;

namespace
{
  // Largest difference of the points' velocities after one step from the formula above.
  double step_and_compare(const bool velocity_change, const double alpha)
  {
    const double        h = 0.1, v0[2] = {1.0, -0.5};
    HostGrid<2, double> grid;
    const double        lower[2] = {-2 * h, -2 * h};
    const int           cells[2] = {16, 10};
    grid.make_dense(lower, h, cells);
    for (long n = 0; n < long(grid.lattice_to_node.size()); ++n)
      {
        int idx[2];
        grid.lattice_coordinates(n, idx);
        grid.fixed_components[n] = idx[1] <= 2 ? 3u : 0u; // no-slip base at y = 0 (and the rows below)
      }
    HostPoints<2, double>      p;
    BodyDescription<2, double> body{2, 1000, {v0[0], v0[1]}, 0};
    const double               lo[2] = {0.3, 0}, hi[2] = {0.9, 0.4};
    add_points(p, grid, lo, hi, body, [](const double *) { return true; });

    auto s                       = mpm_test::quiet_settings<2>(UpdateScheme::musl);
    s.domain_update              = DomainUpdate::none;
    s.flip_fraction              = alpha;
    s.flip_fixed_velocity_change = velocity_change;
    const std::vector<MaterialParameters<double>> materials = {mpm_test::elastic(1e6, 0.3)};
    CpuBackend backend;
    explicit_step<2, GimpShape>(backend, grid.view(), p.view(), materials.data(), s, 1e-4);

    double worst = 0;
    for (int i = 0; i < p.size(); ++i)
      {
        // the starting height (the step moved the point by less than 1e-4 h)
        const double y = p.position[1][i], s_p = y < 0.5 * h ? 0.75 : y < h ? 0.25 : 0.0;
        const double factor = velocity_change ? 1 - s_p : alpha + (1 - alpha) * (1 - s_p);
        for (int d = 0; d < 2; ++d)
          worst = std::max(worst, std::fabs(p.velocity[d][i] - factor * v0[d]));
      }
    return worst;
  }
} // namespace

int main()
{
  for (const double alpha : {1.0, 0.5})
    for (const bool change : {false, true})
      {
        const double e = step_and_compare(change, alpha);
        std::printf("FLIP fraction %.1f, %-15s: largest velocity error %.1e m/s\n", alpha,
                    change ? "velocity change" : "no change", e);
        check(e < 1e-12, change ? "velocity change: v_p = (1 - s_p) v0" : "no change: v_p = a v0 + (1 - a)(1 - s_p) v0",
              e, 1e-12);
      }
  return mpm_test::finish("test_flip_fixed_nodes");
}
