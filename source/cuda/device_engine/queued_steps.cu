// mpm::cuda::DeviceEngine's steps as the host asks for them: one step now (step), or steps
// queued behind each other with their time step computed on the device and replayed as CUDA
// graphs (queue_step, run_queued_step, collect_step). Both run run_step (run_step.cuh).
#include "engine_state.cuh"

namespace mpm
{
  namespace cuda
  {
    template <int dim, typename Real>
    StepReduction<double> DeviceEngine<dim, Real>::step(const StepSettings<dim, double> &settings_in_double,
                                                        const double dt_in_double)
    {
      if (impl->queue.queued != impl->queue.collected)
        throw std::logic_error("DeviceEngine::step: a queued step is not collected yet (collect_step)");
      return converted<double>(run_step(converted<Real>(settings_in_double), static_cast<Real>(dt_in_double)));
    }

    template <int dim, typename Real>
    void DeviceEngine<dim, Real>::queue_step(const StepSettings<dim, double> &settings_in_double,
                                             const TimeStepRule &rule, const double time, const double next_output,
                                             const bool speed_from_host, const double host_speed)
    {
      QueuedSteps<Real> &q = impl->queue;
      if (q.queued - q.collected >= 2)
        throw std::logic_error("DeviceEngine::queue_step: two queued steps are not collected yet (collect_step)");
      // The device's speed is the last record's: only that of the one step queued just before.
      if (!speed_from_host && q.queued - q.collected != 1)
        throw std::logic_error("DeviceEngine::queue_step: the speed from the device needs the step before queued "
                               "and not yet collected; otherwise speed_from_host");
      q.allocate();
      const int          slot   = static_cast<int>(q.queued % 2);
      double            *record = q.records.data() + slot * queued_record_values;
      const double      *last   = q.records.data() + (1 - slot) * queued_record_values;
      const cudaStream_t stream = impl->backend.get_stream();
      queued_time_step_kernel<Real><<<1, 1, 0, stream>>>(rule, time, next_output, speed_from_host, host_speed, last,
                                                         record, q.time_step.data());
      MPM_CUDA_CHECK_LAUNCH();
      StepSettings<dim, Real> s = converted<Real>(settings_in_double);
      s.time_step_on_device     = q.time_step.data();
      impl->backend.keep_reductions_on_device = true;
      try
        {
          run_queued_step(s); // the kernels read the device's time step
        }
      catch (...)
        {
          impl->backend.keep_reductions_on_device = false;
          throw;
        }
      impl->backend.keep_reductions_on_device = false;
      queued_step_record_kernel<Real><<<1, 1, 0, stream>>>(
        static_cast<const StepReduction<Real> *>(impl->backend.last_reduction_on_device()), record);
      MPM_CUDA_CHECK_LAUNCH();
      MPM_CUDA_CHECK(cudaMemcpyAsync(q.host + slot * queued_record_values, record,
                                     queued_record_values * sizeof(double), cudaMemcpyDeviceToHost, stream));
      MPM_CUDA_CHECK(cudaEventRecord(q.copied[slot], stream));
      ++q.queued;
    }

    template <int dim, typename Real>
    void DeviceEngine<dim, Real>::run_queued_step(const StepSettings<dim, Real> &s)
    {
      StepGraphs &graphs = impl->graphs;
      const bool  sort_due = sort_interval > 0 && impl->steps_since_upload % sort_interval == 0;
      const bool  timing_due = impl->timed_from >= 0 && impl->n_timed_steps < 5;
      // Several ranks exchange through the host within the step: no graph there.
      if (!graphs.enabled || sort_due || timing_due || impl->exchange.exchange != nullptr)
        {
          run_step(s, Real(0));
          return;
        }
      // What the step's launches depend on besides the values in device memory.
      std::vector<unsigned char> key;
      append_key(key, s);
      append_key(key, impl->view());
      append_key(key, impl->points.view());
      append_key(key, impl->materials.data());
      append_key(key, impl->shape);
      append_key(key, impl->all_laws);
      append_key(key, impl->disconnects);
      append_key(key, impl->averaging_pending);
      append_key(key, impl->backend.block_size);
      const cudaStream_t stream = impl->backend.get_stream();
      ++graphs.uses;
      if (StepGraphs::Entry *e = graphs.find(key))
        {
          MPM_CUDA_CHECK(cudaGraphLaunch(e->exec, stream));
          ++impl->steps_since_upload; // as run_step does
          impl->averaging_pending = e->pending_after;
          e->last_used            = graphs.uses;
          ++graphs.replays;
          return;
        }
      if (key != graphs.last_direct_key)
        {
          // Settings that change every step (a gravity ramp) would capture every step: a
          // graph only for a step whose launches are those of the step before.
          run_step(s, Real(0));
          graphs.last_direct_key = std::move(key);
          return;
        }
      cudaGraph_t graph = nullptr;
      MPM_CUDA_CHECK(cudaStreamBeginCapture(stream, cudaStreamCaptureModeRelaxed));
      try
        {
          run_step(s, Real(0));
        }
      catch (...)
        {
          cudaStreamEndCapture(stream, &graph);
          if (graph != nullptr)
            cudaGraphDestroy(graph);
          throw;
        }
      MPM_CUDA_CHECK(cudaStreamEndCapture(stream, &graph));
      StepGraphs::Entry &e = graphs.oldest();
      if (e.exec != nullptr)
        {
          MPM_CUDA_CHECK(cudaStreamSynchronize(stream)); // the graph may still run a step queued before
          MPM_CUDA_CHECK(cudaGraphExecDestroy(e.exec));
        }
      e.exec = nullptr;
      const cudaError_t instantiated = cudaGraphInstantiate(&e.exec, graph, 0);
      cudaGraphDestroy(graph);
      MPM_CUDA_CHECK(instantiated);
      e.key           = key;
      e.pending_after = impl->averaging_pending;
      e.last_used     = graphs.uses;
      ++graphs.captures;
      MPM_CUDA_CHECK(cudaGraphLaunch(e.exec, stream)); // the captured step runs now
    }

    template <int dim, typename Real>
    long DeviceEngine<dim, Real>::graph_replays() const
    {
      return impl->graphs.replays;
    }

    template <int dim, typename Real>
    long DeviceEngine<dim, Real>::graph_captures() const
    {
      return impl->graphs.captures;
    }

    template <int dim, typename Real>
    QueuedStep DeviceEngine<dim, Real>::collect_step()
    {
      QueuedSteps<Real> &q = impl->queue;
      if (q.collected == q.queued)
        throw std::logic_error("DeviceEngine::collect_step: no step is queued");
      const int slot = static_cast<int>(q.collected % 2);
      MPM_CUDA_CHECK(cudaEventSynchronize(q.copied[slot]));
      const double *record = q.host + slot * queued_record_values;
      ++q.collected;
      return QueuedStep{{record[0], record[1], record[2]}, record[3]};
    }

    template <int dim, typename Real>
    long DeviceEngine<dim, Real>::queued_steps() const
    {
      return impl->queue.queued - impl->queue.collected;
    }

#define MPM_INSTANTIATE(dim, Real) \
  template StepReduction<double> DeviceEngine<dim, Real>::step(const StepSettings<dim, double> &, const double); \
  template void DeviceEngine<dim, Real>::queue_step(const StepSettings<dim, double> &, const TimeStepRule &, const double, const double, const bool, const double); \
  template void DeviceEngine<dim, Real>::run_queued_step(const StepSettings<dim, Real> &); \
  template long DeviceEngine<dim, Real>::graph_replays() const; \
  template long DeviceEngine<dim, Real>::graph_captures() const; \
  template QueuedStep DeviceEngine<dim, Real>::collect_step(); \
  template long DeviceEngine<dim, Real>::queued_steps() const;

    MPM_DEVICE_ENGINE_TYPES(MPM_INSTANTIATE)
#undef MPM_INSTANTIATE
  } // namespace cuda
} // namespace mpm
