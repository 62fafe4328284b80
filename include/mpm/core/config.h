// Compile-time switches shared by every core header.
#pragma once

// Physics and algorithm functions are plain functions usable on host and device.
#if defined(__CUDACC__)
#  define MPM_HOST_DEVICE __host__ __device__
#else
#  define MPM_HOST_DEVICE
#endif

// A per-point body that a loop calls from one place (point_to_grid): inlined there. GCC left
// it out of line, a call per point and 1% of V3's CPU step (doc/log.md, 2026-12-05).
#define MPM_ALWAYS_INLINE inline __attribute__((always_inline))

namespace mpm
{
  // Stress and strain are stored as 6 Voigt-ordered components in 2D as well:
  // plane strain keeps sigma_zz, which plasticity needs.
  // Order: xx, yy, zz, xy, yz, xz.
  constexpr int n_voigt = 6;

  // State variables of one point besides stress and plastic strain, at most: those a
  // constitutive model written outside the library declares (user_model.h).
  constexpr int max_state_variables = 16;
} // namespace mpm
