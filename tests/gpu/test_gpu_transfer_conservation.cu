// tests/core/test_transfer_conservation.cc on the device: the same checks
// (transfer_conservation_checks.h) with the CUDA backend and device storage.
#include "../core/transfer_conservation_checks.h"
#include "gpu_targets.h"

int main()
{
  if (!mpm_test::cuda_device_present("test_gpu_transfer_conservation"))
    return mpm_test::skip_code;
  try
    {
      mpm_test::check_transfer_conservation<mpm_test::CudaTarget>();
    }
  catch (const std::exception &e)
    {
      std::printf("exception: %s\n", e.what());
      return 1;
    }
  return mpm_test::finish("test_gpu_transfer_conservation");
}
