// The explicit step's time step: the CFL condition on the fastest wave (the elastic wave plus
// the fastest point), cut to land on the end time and on output times. One function for the
// host (the simulator's loop) and the device (a step queued on the GPU before the last one's
// speeds are back on the host): both compute it from the same doubles with the same
// operations, so they agree to the bit, and the host checks that they do.
#pragma once

#include <mpm/core/config.h>
#include <mpm/core/step/settings.h>

namespace mpm
{
  struct TimeStepRule
  {
    bool   adaptive = true;       // false: fixed_step
    double cfl_times_h = 0;       // CFL number x cell size
    double wave_speed  = 0;       // the elastic wave speed c_el
    double fixed_step  = 0;
    double end_time    = 0;
    bool   lands_on_outputs = false; // output interval > 0
    double shortest_landing = 0;     // 1e-12 x end time: the least step to an output time
  };

  // A step queued on the device (DeviceEngine::queue_step) as the host collects it: its
  // reductions and the time step it took.
  struct QueuedStep
  {
    StepReduction<double> reduction;
    double                dt;
  };

  // A speed that is not a number counts as infinite: the step becomes zero and the run's
  // stability check stops it, where a NaN time step would pass every comparison.
  MPM_HOST_DEVICE inline double finite_or_infinite_speed(const double speed)
  {
    return speed != speed ? 1.0 / 0.0 : speed;
  }

  // The step from time to time + dt; next_output is the next output time. The minimum
  // is std::min's: (b < a ? b : a).
  MPM_HOST_DEVICE inline double next_time_step(const TimeStepRule &rule, const double max_speed, const double time,
                                                const double next_output)
  {
    double       dt     = rule.adaptive ? rule.cfl_times_h / (rule.wave_speed + max_speed) : rule.fixed_step;
    const double to_end = rule.end_time - time;
    dt                  = to_end < dt ? to_end : dt;
    if (rule.lands_on_outputs)
      {
        const double to_output = next_output - time;
        const double landing   = to_output < rule.shortest_landing ? rule.shortest_landing : to_output;
        dt                     = landing < dt ? landing : dt;
      }
    return dt;
  }
} // namespace mpm
