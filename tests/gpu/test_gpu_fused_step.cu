// The fused step (step.h, FusedTransfer) on the GPU: each point's kinematics and its P2G of the
// next step in one kernel. Against the unfused step on the host's serial atomic backend (the
// same paths in point order; core/test_fused_step shows that there the fused and the unfused
// step agree bit for bit), per point after 100 steps of P1 (10,024 points):
// - elastic and undamped, where no switch can follow the order of a sum: within 1e-10, the
//   bound of test_gpu_cpu_agreement (its header: about N K u = 1.4e-12 for 100 steps in 3D),
//   MUSL with GIMP unsorted and sorted every 7 steps (a re-sort between two fused steps
//   leaves the carried sums as they are), USL with the cubic B-spline sorted;
// - Drucker-Prager with local damping (switches that round-off can flip): within 100 times
//   the unfused GPU step's own difference from the host, or 1e-10 where that is larger.
#include "../core/check.h"
#include "../core/fused_step_scene.h"
#include "../core/serial_atomic_backend.h"
#include "gpu_targets.h"

#include <algorithm>
#include <cstdio>
#include <string>

using namespace mpm;
using namespace mpm_test;

template <template <int, typename> class Target, typename Shape>
void elastic_agreement(const char *what, const UpdateScheme scheme)
{
  FusedRun run;
  run.n_steps        = 100;
  run.scheme         = scheme;
  run.drucker_prager = false;
  run.damping        = 0;
  HostPoints<3, double> host, gpu;
  p1_fused_or_not<SerialAtomicTarget, Shape>(run, host);
  run.fused = true;
  p1_fused_or_not<Target, Shape>(run, gpu);
  const double difference = largest_difference(host, gpu);
  std::printf("%-52s fused GPU - host %.3e\n", what, difference);
  check_below(difference, 1e-10, (std::string(what) + ": fused GPU against the host").c_str());
}

int main()
{
  if (!cuda_device_present("test_gpu_fused_step"))
    return skip_code;
  try
    {
      elastic_agreement<CudaTarget, GimpShape>("P1 elastic, MUSL, GIMP, unsorted", UpdateScheme::musl);
      elastic_agreement<CudaSortedTarget, GimpShape>("P1 elastic, MUSL, GIMP, sorted every 7", UpdateScheme::musl);
      elastic_agreement<CudaSortedTarget, CubicBSplineShape>("P1 elastic, USL, cubic B-spline, sorted",
                                                             UpdateScheme::usl);
      {
        FusedRun run;
        run.n_steps = 100;
        HostPoints<3, double> host, unfused, fused;
        p1_fused_or_not<SerialAtomicTarget>(run, host);
        p1_fused_or_not<CudaSortedTarget>(run, unfused);
        run.fused = true;
        p1_fused_or_not<CudaSortedTarget>(run, fused);
        const double spread = largest_difference(host, unfused), difference = largest_difference(host, fused);
        std::printf("%-52s unfused GPU - host %.3e, fused GPU - host %.3e\n",
                    "P1 Drucker-Prager, damped, MUSL, GIMP, sorted", spread, difference);
        check_below(difference, std::max(1e-10, 100 * spread), "P1 Drucker-Prager: fused GPU against the host");
      }
    }
  catch (const std::exception &e)
    {
      std::printf("FAILED: %s\n", e.what());
      return 1;
    }
  return finish("test_gpu_fused_step");
}
