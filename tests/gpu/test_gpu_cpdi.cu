// CPDI and CPDI2q (cpdi.h) on the GPU against the CPU, per point, FP64, with the tolerances of
// test_gpu_cpu_agreement.cu (its header says why): the device visits a point's corners and
// adds node by node with atomics (CudaBackend::scatter_stencil), the CPU in its own order.
// CPDI's weights are continuous in the point's position and domain (the corners' linear hats),
// its gradients too, so round-off stays round-off. Scenes: the V1 column at 32 cells, 1000
// steps (damped: the CPU's reordering spread sets the bound), and the spinning block (its
// domains rotate with F, undamped), 2D and 3D, with the FLIP blend and with TPIC; CPDI2q in 2D,
// its corners (state variables) compared too. --short: a tenth of the steps (100 and 30), the same
// comparisons, for compute-sanitizer's racecheck (scripts/dev/gpu_tests_carried.sh).
#include "../core/check.h"
#include "../core/spinning_block.h"
#include "gpu_agreement.h"
#include "gpu_scenes.h"

#include <cmath>
#include <string>

using namespace mpm;
using namespace mpm_test;

// --short: each scene's steps over this.
static long step_divisor = 1;

// Largest difference of CPDI2q's corner offsets (state variables) between two runs, over the cell size.
double corner_difference(const HostPoints<2, double> &ref, const HostPoints<2, double> &other, const int first,
                         const double h)
{
  if (other.n_state_variables() < first + 8)
    return INFINITY;
  double diff = 0;
  for (int k = first; k < first + 8; ++k)
    for (int i = 0; i < ref.size(); ++i)
      diff = std::max(diff, std::abs(ref.state_variables[k][i] - other.state_variables[k][i]));
  return diff / h;
}

template <typename Shape>
void column_agreement(const char *name)
{
  const long            n = 1000 / step_divisor;
  HostPoints<2, double> cpu, gpu, initial;
  ColumnSetup           setup{32, 0.5, DomainUpdate::none};
  setup.max_steps = 0;
  elastic_column<Shape, CpuTarget>(setup, initial);
  setup.max_steps = n;
  elastic_column<Shape, CpuTarget>(setup, cpu, &initial);
  const Difference spread = cpu_reordering_spread(initial, cpu, 10.0 / 32, [&](auto &out, const auto *start) {
    elastic_column<Shape, CpuTarget>(setup, out, start);
  });
  const std::string scene = std::string("V1 column 32 cells (") + name + ")";
  elastic_column<Shape, CudaTarget>(setup, gpu, &initial);
  report<2>(scene.c_str(), compare_points(cpu, gpu, 10.0 / 32), spread, n, true);
  elastic_column<Shape, CudaSortedTarget>(setup, gpu, &initial);
  report<2>((scene + ", GPU sorted every 7").c_str(), compare_points(cpu, gpu, 10.0 / 32), spread, n, true);
  if constexpr (Shape::tracks_corners)
    {
      const double c = corner_difference(cpu, gpu, 0, 10.0 / 32);
      std::printf("%-34s corners: GPU-CPU %.1e h\n", scene.c_str(), c);
      check_below(c, std::max(tolerance, 100 * spread.worst()), (scene + ": corners as the positions").c_str());
    }
}

template <int dim, typename Shape>
void spin_agreement(const char *method, const Transfer transfer)
{
  const long              n = 300 / step_divisor;
  HostPoints<dim, double> cpu, gpu, initial;
  spinning_block<dim, Shape, CpuTarget>(DomainUpdate::none, initial, M_PI / 2, 0, nullptr, transfer);
  const SpinResult on_cpu =
    spinning_block<dim, Shape, CpuTarget>(DomainUpdate::none, cpu, M_PI / 2, n, &initial, transfer);
  const std::string scene = std::string("spinning block ") + method + (dim == 2 ? " (2D)" : " (3D)");
  std::printf("%s: angular momentum kept %.6f on the CPU\n", scene.c_str(), on_cpu.momentum_ratio);
  spinning_block<dim, Shape, CudaTarget>(DomainUpdate::none, gpu, M_PI / 2, n, &initial, transfer);
  report<dim>(scene.c_str(), compare_points(cpu, gpu, 0.125), Difference(), n, false);
  spinning_block<dim, Shape, CudaSortedTarget>(DomainUpdate::none, gpu, M_PI / 2, n, &initial, transfer);
  report<dim>((scene + ", GPU sorted every 7").c_str(), compare_points(cpu, gpu, 0.125), Difference(), n, false);
  if constexpr (Shape::tracks_corners)
    {
      const double c = corner_difference(cpu, gpu, transfer.apic ? dim * dim : 0, 0.125);
      std::printf("%-34s corners: GPU-CPU %.1e h\n", scene.c_str(), c);
      check_below(c, tolerance, (scene + ": corners within 1e-10 h").c_str());
    }
}

int main(int argc, char **argv)
{
  int        usage_error = 0;
  const bool short_form  = short_form_option(argc, argv, "test_gpu_cpdi", &usage_error);
  if (usage_error != 0)
    return usage_error;
  if (!cuda_device_present("test_gpu_cpdi"))
    return skip_code;
  step_divisor = short_form ? 10 : 1;
  try
    {
      const Transfer tpic{0, true, AffineMatrix::velocity_gradient};
      column_agreement<CpdiShape>("CPDI");
      column_agreement<Cpdi2qShape>("CPDI2q");
      spin_agreement<2, CpdiShape>("CPDI FLIP", {});
      spin_agreement<3, CpdiShape>("CPDI FLIP", {});
      spin_agreement<2, CpdiShape>("CPDI TPIC", tpic);
      spin_agreement<3, CpdiShape>("CPDI TPIC", tpic);
      // CPDI2q: the corners move with the grid (the kinematics), kept in state variables
      spin_agreement<2, Cpdi2qShape>("CPDI2q FLIP", {});
      spin_agreement<2, Cpdi2qShape>("CPDI2q TPIC", tpic);
    }
  catch (const std::exception &e)
    {
      std::printf("exception: %s\n", e.what());
      return 1;
    }
  return finish("test_gpu_cpdi");
}
