// tests/core/test_transfer_conservation.cc on the device: the same checks
// (transfer_conservation_checks.h) with the CUDA backend and device storage.
// --short: 10 steps where the test takes 400-500, for compute-sanitizer's racecheck, which
// does not finish the whole test in minutes (scripts/gpu_tests_carried.sh).
#include "../core/transfer_conservation_checks.h"
#include "gpu_targets.h"

#include <cstring>

int main(int argc, char **argv)
{
  if (!mpm_test::cuda_device_present("test_gpu_transfer_conservation"))
    return mpm_test::skip_code;
  const bool short_form = argc > 1 && std::strcmp(argv[1], "--short") == 0;
  if (argc > 2 || (argc == 2 && !short_form))
    {
      std::printf("usage: test_gpu_transfer_conservation [--short]\n");
      return 2;
    }
  std::setvbuf(stdout, nullptr, _IOLBF, 0); // a sanitizer's log shows how far it came
  try
    {
      mpm_test::check_transfer_conservation<mpm_test::CudaTarget>(short_form);
    }
  catch (const std::exception &e)
    {
      std::printf("exception: %s\n", e.what());
      return 1;
    }
  return mpm_test::finish("test_gpu_transfer_conservation");
}
