// Minimal checking helpers for the core tests (no test framework is needed on the GPU host).
#pragma once

#include <cmath>
#include <cstdio>
#include <cstdlib>

namespace mpm_test
{
  inline int &failures()
  {
    static int n = 0;
    return n;
  }

  inline void check(const bool ok, const char *what, const double value = 0, const double limit = 0)
  {
    if (!ok)
      {
        ++failures();
        std::printf("FAILED: %s (value %.6e, limit %.6e)\n", what, value, limit);
      }
  }

  inline void check_below(const double value, const double limit, const char *what)
  {
    check(std::isfinite(value) && value <= limit, what, value, limit);
  }

  inline int finish(const char *name)
  {
    if (failures() == 0)
      std::printf("%s: all checks passed\n", name);
    else
      std::printf("%s: %d checks failed\n", name, failures());
    return failures() == 0 ? EXIT_SUCCESS : EXIT_FAILURE;
  }
} // namespace mpm_test
