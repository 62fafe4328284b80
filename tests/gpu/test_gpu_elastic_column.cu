// tests/core/test_elastic_column.cc on the device: the same checks (elastic_column_checks.h)
// with the CUDA backend.
#include "../core/elastic_column_checks.h"
#include "gpu_targets.h"

int main()
{
  if (!mpm_test::cuda_device_present("test_gpu_elastic_column"))
    return mpm_test::skip_code;
  try
    {
      mpm_test::check_column_convergence<mpm_test::CudaTarget>({16, 32, 64}, true);
      mpm_test::check_bspline_column<mpm::QuadraticBSplineShape, mpm_test::CudaTarget>("quadratic B-spline",
                                                                                        {16, 32, 64}, true);
      mpm_test::check_bspline_column<mpm::CubicBSplineShape, mpm_test::CudaTarget>("cubic B-spline", {16, 32, 64},
                                                                                    true);
      mpm_test::check_bspline_gimp_column<mpm_test::CudaTarget>({8, 16, 32, 64, 128, 256}, true);
    }
  catch (const std::exception &e)
    {
      std::printf("exception: %s\n", e.what());
      return 1;
    }
  return mpm_test::finish("test_gpu_elastic_column");
}
