// DeviceEngine<2, double>::run_step (run_step.cuh).
#include "run_step.cuh"

template mpm::StepReduction<double>
mpm::cuda::DeviceEngine<2, double>::run_step(const mpm::StepSettings<2, double> &, double);
