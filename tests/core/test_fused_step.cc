// The fused step (step.h, FusedTransfer): each point's kinematics followed by its P2G of the
// next step, in one pass. It must add the same values into the same sums as the unfused
// step's P2G pass. On a backend that runs the device's atomic-scatter paths serially in point
// order (serial_atomic_backend.h) the adds also come in the same order, so the fused run
// must equal the unfused one bit for bit: P1 with Drucker-Prager and local damping (the
// gravity ramped, so a P2G with this step's gravity instead of the next one's differs),
// MUSL and USL, every shape function of the 3D step. That backend itself is checked against
// the CPU backend (the same step, sums in another order: within the round-off of
// test_gpu_cpu_agreement's bound). The GPU twin is tests/gpu/test_gpu_fused_step.
#include "check.h"
#include "fused_step_scene.h"
#include "serial_atomic_backend.h"

#include <mpm/core/backend/cpu_backend.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

using namespace mpm;
using namespace mpm_test;

namespace
{
  // How far the run went: the largest displacement in cells (the comparison means something
  // only where the points moved and yielded).
  void print_motion(const char *what, const HostPoints<3, double> &p, const HostPoints<3, double> &initial)
  {
    double moved = 0, plastic = 0;
    for (int i = 0; i < p.size(); ++i)
      {
        for (int d = 0; d < 3; ++d)
          moved = std::max(moved, std::abs(p.position[d][i] - initial.position[d][i]) / mpm_bench::P1::h);
        plastic = std::max(plastic, p.plastic_strain[i]);
      }
    std::printf("%-44s largest displacement %.3e cells, largest plastic strain %.3e\n", what, moved, plastic);
  }

  template <typename Shape>
  void fused_equals_unfused(const char *what, const UpdateScheme scheme, const long n_steps = 150)
  {
    FusedRun run;
    run.scheme = scheme;
    HostPoints<3, double> unfused, fused, initial;
    run.n_steps = 0;
    p1_fused_or_not<SerialAtomicTarget, Shape>(run, initial);
    run.n_steps = n_steps;
    const double t = p1_fused_or_not<SerialAtomicTarget, Shape>(run, unfused);
    run.fused      = true;
    p1_fused_or_not<SerialAtomicTarget, Shape>(run, fused);
    print_motion(what, unfused, initial);
    const double difference = largest_difference(unfused, fused);
    std::printf("%-44s %ld steps to t = %.3f s: fused - unfused %.3e\n", what, run.n_steps, t, difference);
    check(difference == 0, (std::string(what) + ": the fused step differs from the unfused one").c_str(),
          difference, 0);
  }
} // namespace

int main()
{
  fused_equals_unfused<GimpShape>("P1, Drucker-Prager, MUSL, GIMP", UpdateScheme::musl);
  fused_equals_unfused<CubicBSplineShape>("P1, Drucker-Prager, USL, cubic B-spline", UpdateScheme::usl);
  // The other stencils, fewer steps: the quadratic B-spline, the cubic B-spline GIMP, linear
  // (MUSL: USL with linear weights blows up here), and CPDI (corner by corner, not a tensor product).
  fused_equals_unfused<QuadraticBSplineShape>("P1, DP, MUSL, quadratic B-spline", UpdateScheme::musl, 80);
  fused_equals_unfused<CubicBSplineGimpShape>("P1, DP, MUSL, cubic B-spline GIMP", UpdateScheme::musl, 80);
  fused_equals_unfused<LinearShape>("P1, DP, MUSL, linear", UpdateScheme::musl, 80);
  fused_equals_unfused<CpdiShape>("P1, DP, MUSL, CPDI", UpdateScheme::musl, 80);

  // The serial atomic backend against the CPU backend: elastic, undamped (no switch that the
  // order of a sum can flip), 100 steps. test_gpu_cpu_agreement's bound for 3D after N steps
  // is about N K u = 100 x 125 x 1.1e-16 = 1.4e-12; it allows 1e-10, as here.
  {
    FusedRun run;
    run.n_steps        = 100;
    run.drucker_prager = false;
    run.damping        = 0;
    HostPoints<3, double> cpu, serial;
    p1_fused_or_not<CpuTarget>(run, cpu);
    p1_fused_or_not<SerialAtomicTarget>(run, serial);
    const double difference = largest_difference(cpu, serial);
    std::printf("%-44s serial atomic - CPU backend %.3e\n", "P1 elastic, undamped, MUSL, GIMP", difference);
    check_below(difference, 1e-10, "the serial atomic backend against the CPU backend");
  }

  // What the fused step refuses.
  {
    HostGrid<3, double>                     grid;
    HostPoints<3, double>                   points;
    std::vector<MaterialParameters<double>> materials;
    mpm_bench::make_p1(2, grid, points, materials);
    StepSettings<3, double>  s = mpm_bench::p1_settings<double>();
    FusedTransfer<3, double> fused;
    fused.carry_next = true;
    auto step        = [&](auto &backend, const StepSettings<3, double> &settings) {
      explicit_step<3, GimpShape>(backend, grid.view(), points.view(), materials.data(), settings, 1e-3,
                                  NoGridExchange(), nullptr, &fused);
    };
    CpuBackend          cpu;
    SerialAtomicBackend serial;
    check(throws_naming([&] { step(cpu, s); }, "a backend whose scatter is atomic"), "fused on the CPU backend");
    StepSettings<3, double> averaged = s;
    averaged.pressure_averaging      = true;
    check(throws_naming([&] { step(serial, averaged); }, "without pressure averaging"), "fused with averaging");
    StepSettings<3, double> usf = s;
    usf.scheme                  = UpdateScheme::usf;
    check(throws_naming([&] { step(serial, usf); }, "runs MUSL and USL"), "fused with USF");
  }
  return finish("test_fused_step");
}
