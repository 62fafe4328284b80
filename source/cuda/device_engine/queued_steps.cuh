// The device engine's queued steps (private to source/cuda/device_engine/): their records in
// pinned host memory, the kernels that compute a queued step's time step on the device, the
// engine's own stream and the CUDA graphs that replay a step's launches.
#pragma once

#include <mpm/core/backend/cuda_backend.h>
#include <mpm/core/time_step_rule.h>
#include <mpm/cuda/device_engine.h>

#include <cstring>
#include <vector>

namespace mpm
{
  namespace cuda
  {
    // Steps queued behind each other (DeviceEngine::queue_step): each step's time step is
    // computed on the device from the last step's largest speed, and each step's record (its
    // reductions and its time step) is copied into one of two pinned host slots that the
    // host reads when it collects the step, one step behind the device.
    constexpr int queued_record_values = 4; // max speed, power of gravity, max removed speed, dt

    template <typename Real>
    struct QueuedSteps
    {
      DeviceArray<double> records; // two slots of queued_record_values
      DeviceArray<Real>   time_step; // the queued step's dt, in the points' precision
      double             *host = nullptr; // pinned: two slots
      cudaEvent_t         copied[2] = {nullptr, nullptr};
      long                queued = 0, collected = 0;

      void allocate()
      {
        if (host != nullptr)
          return;
        records.resize(2 * queued_record_values);
        time_step.resize(1);
        MPM_CUDA_CHECK(cudaMallocHost(&host, 2 * queued_record_values * sizeof(double)));
        for (cudaEvent_t &e : copied)
          MPM_CUDA_CHECK(cudaEventCreateWithFlags(&e, cudaEventDisableTiming));
      }

      ~QueuedSteps()
      {
        // No throwing from a destructor: errors here are ignored.
        for (cudaEvent_t e : copied)
          if (e != nullptr)
            cudaEventDestroy(e);
        if (host != nullptr)
          cudaFreeHost(host);
      }
    };

    // The queued step's time step, from the last step's record (or the host's speed for the
    // first step queued after one that was not), by the host's rule: the same doubles, the
    // same operations.
    template <typename Real>
    __global__ void queued_time_step_kernel(const TimeStepRule rule, const double time, const double next_output,
                                            const bool speed_from_host, const double host_speed,
                                            const double *last_record, double *record, Real *time_step)
    {
      const double speed = speed_from_host ? host_speed : finite_or_infinite_speed(last_record[0]);
      const double dt    = next_time_step(rule, speed, time, next_output);
      record[3]          = dt;
      *time_step         = static_cast<Real>(dt);
    }

    // The step's reductions (left on the device by the backend) into its record, in double
    // as the host converts them.
    template <typename Real>
    __global__ void queued_step_record_kernel(const StepReduction<Real> *reduction, double *record)
    {
      record[0] = static_cast<double>(reduction->max_speed);
      record[1] = static_cast<double>(reduction->gravity_power);
      record[2] = static_cast<double>(reduction->max_removed_speed);
    }

    // The engine's stream: created (a blocking stream, so that it stays ordered with the
    // legacy stream's copies as before), because a step can be captured into a CUDA graph on
    // a stream of its own only.
    struct OwnStream
    {
      cudaStream_t stream = nullptr;
      OwnStream() { MPM_CUDA_CHECK(cudaStreamCreate(&stream)); }
      ~OwnStream() { cudaStreamDestroy(stream); } // no throwing from a destructor
      OwnStream(const OwnStream &)            = delete;
      OwnStream &operator=(const OwnStream &) = delete;
    };

    // Queued steps whose launches are those of an earlier one (the same settings, arrays and
    // sizes; only the values in device memory differ) replay that step's launches as one CUDA
    // graph: one launch on the host instead of a dozen. A graph per key of the step's launch
    // arguments, the two latest (the re-sort swaps the point arrays between two buffers).
    struct StepGraphs
    {
      struct Entry
      {
        std::vector<unsigned char> key;
        cudaGraphExec_t            exec          = nullptr;
        bool                       pending_after = false; // the host's averaging flag after the step
        long                       last_used     = 0;
      };
      Entry                      entries[2];
      std::vector<unsigned char> last_direct_key; // the last step run without a graph
      long                       captures = 0, replays = 0, uses = 0;
      bool                       enabled  = true; // MPM_CUDA_GRAPHS=0: off

      Entry *find(const std::vector<unsigned char> &key)
      {
        for (Entry &e : entries)
          if (e.exec != nullptr && e.key == key)
            return &e;
        return nullptr;
      }
      Entry &oldest() { return entries[0].last_used <= entries[1].last_used ? entries[0] : entries[1]; }
      void   clear()
      {
        if (entries[0].exec != nullptr || entries[1].exec != nullptr)
          cudaDeviceSynchronize(); // no graph destroyed while it runs (errors ignored: destructor)
        for (Entry &e : entries)
          {
            if (e.exec != nullptr)
              cudaGraphExecDestroy(e.exec);
            e = Entry();
          }
        last_direct_key.clear();
      }
      ~StepGraphs() { clear(); }
    };
  } // namespace cuda
} // namespace mpm
