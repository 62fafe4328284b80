// Compile-time switches shared by every core header.
#pragma once

// Physics and algorithm functions are plain functions usable on host and device.
#if defined(__CUDACC__)
#  define MPM_HOST_DEVICE __host__ __device__
#else
#  define MPM_HOST_DEVICE
#endif

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
