// Hints to the GPU's memory system: fetch an entry into L2 now, so that a load issued
// later (after stores the compiler may not move it above) finds it there instead of
// waiting on DRAM. No effect on any result; nothing on the host.
#pragma once

#include <mpm/core/config.h>

namespace mpm
{
  template <typename T>
  MPM_HOST_DEVICE inline void prefetch_to_l2(const T *address)
  {
#if defined(__CUDA_ARCH__)
#  if defined(MPM_PREFETCH_L1)
    asm volatile("prefetch.global.L1 [%0];" ::"l"(address));
#  else
    asm volatile("prefetch.global.L2 [%0];" ::"l"(address));
#  endif
#else
    (void)address;
#endif
  }
} // namespace mpm
