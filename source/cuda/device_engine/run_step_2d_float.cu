// DeviceEngine<2, float>::run_step (run_step.cuh).
#include "run_step.cuh"

template mpm::StepReduction<float>
mpm::cuda::DeviceEngine<2, float>::run_step(const mpm::StepSettings<2, float> &, float);
