// V1 elastic column on the CPU (checks in elastic_column_checks.h; the GPU twin is
// tests/gpu/test_gpu_elastic_column.cu). "--explore" prints a wider table.
#include "elastic_column_checks.h"

#include <cstring>

int main(int argc, char **argv)
{
  const bool explore = argc > 1 && std::strcmp(argv[1], "--explore") == 0;
  if (explore)
    {
      mpm_test::check_column_convergence<mpm_test::CpuTarget>({2, 4, 8, 16, 32, 64, 128, 256}, false);
      const std::vector<int> levels{2, 4, 8, 16, 32, 64, 128, 256};
      mpm_test::check_bspline_column<mpm::QuadraticBSplineShape, mpm_test::CpuTarget>("quadratic B-spline", levels,
                                                                                       false);
      mpm_test::check_bspline_column<mpm::CubicBSplineShape, mpm_test::CpuTarget>("cubic B-spline", levels, false);
      mpm_test::check_bspline_gimp_column<mpm_test::CpuTarget>(levels, false);
    }
  else
    {
      mpm_test::check_column_convergence<mpm_test::CpuTarget>({16, 32, 64}, true);
      mpm_test::check_bspline_column<mpm::QuadraticBSplineShape, mpm_test::CpuTarget>("quadratic B-spline",
                                                                                       {16, 32, 64}, true);
      mpm_test::check_bspline_column<mpm::CubicBSplineShape, mpm_test::CpuTarget>("cubic B-spline", {16, 32, 64},
                                                                                   true);
      mpm_test::check_bspline_gimp_column<mpm_test::CpuTarget>({8, 16, 32, 64, 128, 256}, true);
    }
  return mpm_test::finish("test_elastic_column");
}
