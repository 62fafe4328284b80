// tests/core/test_transfer_conservation.cc on the device: the same checks
// (transfer_conservation_checks.h) with the CUDA backend and device storage.
// --short: 10 steps where the test takes 400-500, for compute-sanitizer's racecheck, which
// does not finish the whole test in minutes (scripts/dev/gpu_tests_carried.sh).
#include "../core/transfer_conservation_checks.h"
#include "gpu_targets.h"

int main(int argc, char **argv)
{
  int        usage_error = 0;
  const bool short_form  = mpm_test::short_form_option(argc, argv, "test_gpu_transfer_conservation", &usage_error);
  if (usage_error != 0)
    return usage_error;
  if (!mpm_test::cuda_device_present("test_gpu_transfer_conservation"))
    return mpm_test::skip_code;
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
