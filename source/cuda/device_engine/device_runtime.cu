// The CUDA runtime as the deal.II layer asks for it: how many devices, which one a rank
// uses, their description, whether the exchange overlaps the step.
#include <mpm/core/backend/cuda_backend.h>
#include <mpm/cuda/device_engine.h>

#include <cstdio>
#include <cstdlib>
#include <string>

namespace mpm
{
  namespace cuda
  {
    int device_count(std::string *why)
    {
      int               n    = 0;
      const cudaError_t code = cudaGetDeviceCount(&n);
      if (code != cudaSuccess)
        {
          if (why)
            *why = std::string(cudaGetErrorName(code)) + ": " + cudaGetErrorString(code);
          (void)cudaGetLastError();
          return 0;
        }
      if (n == 0 && why)
        *why = "the CUDA runtime found no device";
      return n;
    }

    void initialise_device()
    {
      if (cudaFree(nullptr) != cudaSuccess)
        (void)cudaGetLastError(); // reported again, with context, by device_count()
    }

    std::string device_description()
    {
      int device = 0;
      MPM_CUDA_CHECK(cudaGetDevice(&device));
      cudaDeviceProp prop;
      MPM_CUDA_CHECK(cudaGetDeviceProperties(&prop, device));
      char text[256];
      std::snprintf(text, sizeof(text), "%s (sm_%d%d, %d SMs, %.1f GB)", prop.name, prop.major, prop.minor,
                    prop.multiProcessorCount, prop.totalGlobalMem / 1e9);
      return text;
    }

    int use_device_of_local_rank(const int node_local_rank)
    {
      const int n = device_count();
      if (n == 0)
        return 0; // the engine's constructor reports it
      const int device = node_local_rank % n;
      MPM_CUDA_CHECK(cudaSetDevice(device));
      return device;
    }

    bool exchange_overlap_enabled()
    {
      const char *overlap = std::getenv("MPM_CUDA_OVERLAP");
      return overlap == nullptr || overlap[0] != '0';
    }
  } // namespace cuda
} // namespace mpm
