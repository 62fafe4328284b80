// Error checking for every CUDA runtime call and kernel launch of the CUDA backend.
// A failing call throws mpm::CudaError naming the call, the file and the line, so a
// driver can report it (and, in tests, fail) instead of continuing on garbage.
#pragma once

#include <cuda_runtime.h>

#include <stdexcept>
#include <string>

namespace mpm
{
  class CudaError : public std::runtime_error
  {
  public:
    CudaError(const cudaError_t code, const std::string &what)
      : std::runtime_error(what)
      , code(code)
    {}
    cudaError_t code;
  };

  namespace cuda_detail
  {
    inline void check(const cudaError_t code, const char *call, const char *file, const int line)
    {
      if (code != cudaSuccess)
        throw CudaError(code, std::string(file) + ":" + std::to_string(line) + ": " + call + " failed: " +
                                cudaGetErrorName(code) + " (" + cudaGetErrorString(code) + ")");
    }
  } // namespace cuda_detail

  // Number of usable CUDA devices; 0 where there is no device or no driver
  // (cudaGetDeviceCount's error is cleared, so later calls are not poisoned).
  inline int cuda_device_count()
  {
    int             n    = 0;
    const cudaError_t code = cudaGetDeviceCount(&n);
    if (code != cudaSuccess)
      {
        (void)cudaGetLastError();
        return 0;
      }
    return n;
  }
} // namespace mpm

#define MPM_CUDA_CHECK(call) ::mpm::cuda_detail::check((call), #call, __FILE__, __LINE__)
// After a kernel launch: launch-configuration errors are reported at once; errors
// inside the kernel surface at the next synchronising call, which is checked too.
#define MPM_CUDA_CHECK_LAUNCH() ::mpm::cuda_detail::check(cudaGetLastError(), "kernel launch", __FILE__, __LINE__)
