// CPDI (cpdi.h) on the GPU against the CPU, per point, FP64, with the tolerances of
// test_gpu_cpu_agreement.cu (its header says why): the device visits a point's corners and
// adds node by node with atomics (CudaBackend::scatter_stencil), the CPU in its own order.
// CPDI's weights are continuous in the point's position and domain (the corners' linear hats),
// its gradients too, so round-off stays round-off. Scenes: the V1 column at 32 cells, 1000
// steps (damped: the CPU's reordering spread sets the bound), and the spinning block (its
// domains rotate with F, undamped), 2D and 3D, with the FLIP blend and with TPIC.
#include "../core/check.h"
#include "../core/spinning_block.h"
#include "gpu_agreement.h"
#include "gpu_scenes.h"

#include <cmath>
#include <string>

using namespace mpm;
using namespace mpm_test;

void column_agreement()
{
  const long            n = 1000;
  HostPoints<2, double> cpu, gpu, initial;
  ColumnSetup           setup{32, 0.5, DomainUpdate::none};
  setup.max_steps = 0;
  elastic_column<CpdiShape, CpuTarget>(setup, initial);
  setup.max_steps = n;
  elastic_column<CpdiShape, CpuTarget>(setup, cpu, &initial);
  const Difference spread = cpu_reordering_spread(initial, cpu, 10.0 / 32, [&](auto &out, const auto *start) {
    elastic_column<CpdiShape, CpuTarget>(setup, out, start);
  });
  elastic_column<CpdiShape, CudaTarget>(setup, gpu, &initial);
  report<2>("V1 column 32 cells (CPDI)", compare_points(cpu, gpu, 10.0 / 32), spread, n, true);
  elastic_column<CpdiShape, CudaSortedTarget>(setup, gpu, &initial);
  report<2>("V1 column CPDI, GPU sorted every 7", compare_points(cpu, gpu, 10.0 / 32), spread, n, true);
}

template <int dim>
void spin_agreement(const char *method, const Transfer transfer)
{
  const long              n = 300;
  HostPoints<dim, double> cpu, gpu, initial;
  spinning_block<dim, CpdiShape, CpuTarget>(DomainUpdate::none, initial, M_PI / 2, 0, nullptr, transfer);
  const SpinResult on_cpu =
    spinning_block<dim, CpdiShape, CpuTarget>(DomainUpdate::none, cpu, M_PI / 2, n, &initial, transfer);
  const std::string scene = std::string("spinning block CPDI ") + method + (dim == 2 ? " (2D)" : " (3D)");
  std::printf("%s: angular momentum kept %.6f on the CPU\n", scene.c_str(), on_cpu.momentum_ratio);
  spinning_block<dim, CpdiShape, CudaTarget>(DomainUpdate::none, gpu, M_PI / 2, n, &initial, transfer);
  report<dim>(scene.c_str(), compare_points(cpu, gpu, 0.125), Difference(), n, false);
  spinning_block<dim, CpdiShape, CudaSortedTarget>(DomainUpdate::none, gpu, M_PI / 2, n, &initial, transfer);
  report<dim>((scene + ", GPU sorted every 7").c_str(), compare_points(cpu, gpu, 0.125), Difference(), n, false);
}

int main()
{
  if (!cuda_device_present("test_gpu_cpdi"))
    return skip_code;
  try
    {
      column_agreement();
      spin_agreement<2>("FLIP", {});
      spin_agreement<3>("FLIP", {});
      spin_agreement<2>("TPIC", {0, true, AffineMatrix::velocity_gradient});
      spin_agreement<3>("TPIC", {0, true, AffineMatrix::velocity_gradient});
    }
  catch (const std::exception &e)
    {
      std::printf("exception: %s\n", e.what());
      return 1;
    }
  return finish("test_gpu_cpdi");
}
