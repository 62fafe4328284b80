// The shape family's test member (`test wide linear`, include/mpm/core/shape/test_wide_linear_shape.h:
// linear's hats on GIMP's three-node stencil) on the GPU against the CPU, per point, FP64, with
// the tolerances of test_gpu_cpu_agreement.cu (its header says why): the V1 column at 32 cells,
// 1000 steps (damped: within 100x the CPU's own reordering spread), unsorted and with the device's
// sorts every 7 steps (their key is the member's first stencil node), and the undamped spinning
// block, 2D and 3D, with the FLIP blend and with TPIC (within 1e-10). On the GPU the member also
// runs as linear does: the column's points against linear's on the GPU. --short: a tenth of the
// steps, for compute-sanitizer.
#include "../core/check.h"
#include "../core/spinning_block.h"
#include "gpu_agreement.h"
#include "gpu_scenes.h"

#include <mpm/core/shape/test_wide_linear_shape.h>

#include <cmath>
#include <string>

using namespace mpm;
using namespace mpm_test;

static long step_divisor = 1;

void column_agreement()
{
  const long            n = 1000 / step_divisor;
  HostPoints<2, double> cpu, gpu, initial, gpu_linear;
  ColumnSetup           setup{32, 0.5, DomainUpdate::none};
  setup.max_steps = 0;
  elastic_column<TestWideLinearShape, CpuTarget>(setup, initial);
  setup.max_steps = n;
  elastic_column<TestWideLinearShape, CpuTarget>(setup, cpu, &initial);
  const Difference spread = cpu_reordering_spread(initial, cpu, 10.0 / 32, [&](auto &out, const auto *start) {
    elastic_column<TestWideLinearShape, CpuTarget>(setup, out, start);
  });
  const std::string scene = "V1 column 32 cells (test wide linear)";
  elastic_column<TestWideLinearShape, CudaTarget>(setup, gpu, &initial);
  report<2>(scene.c_str(), compare_points(cpu, gpu, 10.0 / 32), spread, n, true);
  elastic_column<TestWideLinearShape, CudaSortedTarget>(setup, gpu, &initial);
  report<2>((scene + ", GPU sorted every 7").c_str(), compare_points(cpu, gpu, 10.0 / 32), spread, n, true);
  elastic_column<LinearShape, CudaTarget>(setup, gpu_linear, &initial);
  report<2>("V1 column 32 cells, GPU: wide vs linear", compare_points(gpu_linear, gpu, 10.0 / 32), spread, n, true);
}

template <int dim>
void spin_agreement(const char *method, const Transfer transfer)
{
  const long              n = 300 / step_divisor;
  HostPoints<dim, double> cpu, gpu, initial;
  spinning_block<dim, TestWideLinearShape, CpuTarget>(DomainUpdate::none, initial, M_PI / 2, 0, nullptr, transfer);
  const SpinResult on_cpu =
    spinning_block<dim, TestWideLinearShape, CpuTarget>(DomainUpdate::none, cpu, M_PI / 2, n, &initial, transfer);
  const std::string scene = std::string("spinning block wide linear ") + method + (dim == 2 ? " (2D)" : " (3D)");
  std::printf("%s: angular momentum kept %.6f on the CPU\n", scene.c_str(), on_cpu.momentum_ratio);
  spinning_block<dim, TestWideLinearShape, CudaTarget>(DomainUpdate::none, gpu, M_PI / 2, n, &initial, transfer);
  report<dim>(scene.c_str(), compare_points(cpu, gpu, 0.125), Difference(), n, false);
  spinning_block<dim, TestWideLinearShape, CudaSortedTarget>(DomainUpdate::none, gpu, M_PI / 2, n, &initial, transfer);
  report<dim>((scene + ", GPU sorted every 7").c_str(), compare_points(cpu, gpu, 0.125), Difference(), n, false);
}

int main(int argc, char **argv)
{
  int        usage_error = 0;
  const bool short_form  = short_form_option(argc, argv, "test_gpu_shape_family", &usage_error);
  if (usage_error != 0)
    return usage_error;
  if (!cuda_device_present("test_gpu_shape_family"))
    return skip_code;
  step_divisor = short_form ? 10 : 1;
  try
    {
      const Transfer tpic{0, true, AffineMatrix::velocity_gradient};
      column_agreement();
      spin_agreement<2>("FLIP", {});
      spin_agreement<3>("FLIP", {});
      spin_agreement<2>("TPIC", tpic);
      spin_agreement<3>("TPIC", tpic);
    }
  catch (const std::exception &e)
    {
      std::printf("exception: %s\n", e.what());
      return 1;
    }
  return finish("test_gpu_shape_family");
}
