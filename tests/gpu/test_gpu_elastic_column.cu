// tests/core/test_elastic_column.cc on the device: V1 elastic column, cpGIMP (F_ii domain
// update), pure FLIP, MUSL, D = 0.05, run to 2 t_ramp at 16, 32, 64 cells: the error
// decreases, the observed order between the two finest levels is >= 1.5, the finest
// error is below 1e-3, and sMPM's cell-crossing noise is at least 5x GIMP's error.
#include "../core/check.h"
#include "gpu_scenes.h"

using namespace mpm;
using namespace mpm_test;

int main()
{
  if (!cuda_device_present("test_gpu_elastic_column"))
    return skip_code;
  try
    {
      std::printf("%8s %12s %12s %10s %8s\n", "cells", "error GIMP", "error sMPM", "steps", "order");
      std::vector<double> errors;
      double              last_smpm = 0;
      for (const int n : {16, 32, 64})
        {
          HostPoints<2, double> points;
          const SceneResult gimp = column<GimpShape, CudaTarget>(n, points, -1, nullptr, DomainUpdate::stretch, 0.05);
          const SceneResult smpm = column<LinearShape, CudaTarget>(n, points, -1, nullptr, DomainUpdate::none, 0.05);
          const double order = errors.empty() ? 0 : std::log2(errors.back() / gimp.error);
          errors.push_back(gimp.error);
          last_smpm = smpm.error;
          std::printf("%8d %12.4e %12.4e %10ld %8.2f\n", n, gimp.error, smpm.error, gimp.n_steps, order);
        }
      const double order = std::log2(errors[errors.size() - 2] / errors.back());
      for (size_t i = 1; i < errors.size(); ++i)
        check(errors[i] < errors[i - 1], "GIMP error decreases with refinement", errors[i], errors[i - 1]);
      check(order >= 1.5, "observed order between the finest levels >= 1.5", order, 1.5);
      check_below(errors.back(), 1e-3, "finest-level error below 1e-3");
      check(last_smpm > 5 * errors.back(), "sMPM error exceeds 5x GIMP's", last_smpm, 5 * errors.back());
    }
  catch (const std::exception &e)
    {
      std::printf("exception: %s\n", e.what());
      return 1;
    }
  return finish("test_gpu_elastic_column");
}
