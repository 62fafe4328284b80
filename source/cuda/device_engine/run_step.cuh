// mpm::cuda::DeviceEngine::run_step: one step of the core's step.h on the device (the sort
// every sort_interval steps, pressure averaging's cell arrays, the kernels' variant). The
// step's kernels are most of the engine's compile time, so each (dim, Real) instantiates it
// in a source file of its own (run_step_2d_double.cu, ...), compiled in parallel.
#pragma once

#include "engine_state.cuh"

namespace mpm
{
  namespace cuda
  {
    template <int dim, typename Real>
    StepReduction<Real> DeviceEngine<dim, Real>::run_step(const StepSettings<dim, Real> &s, const Real dt)
    {
      GridView<dim, Real> g = impl->grid.view();
      if (sort_interval > 0 && impl->steps_since_upload % sort_interval == 0)
        {
          // The overlap's split needs every point's home cell.
          const bool split = impl->cells_before_overlap.size() > 0 &&
                             static_cast<int>(impl->home_cells.size()) == impl->points.size();
          const long         *home  = split ? impl->home_cells.data() : nullptr;
          const std::uint8_t *cells = split ? impl->cells_before_overlap.data() : nullptr;
          int                 first = -1;
          with_shape(impl->shape, [&](auto member) { // CPDI: by the point's cell (cuda_point_order.h)
            first = impl->order.template sort<decltype(member)>(impl->backend, g, impl->points, home, cells);
          });
          impl->home_by_slot_stale    = true;
          impl->exchange.first_points = first;
          if (first >= 0 && impl->points.size() > 0)
            {
              impl->first_share_sum += static_cast<double>(first) / impl->points.size();
              ++impl->n_split_sorts;
            }
        }
      ++impl->steps_since_upload;
      if (s.pressure_averaging)
        {
          if (!HasCellArrays<GridView<dim, Real>>::value)
            throw std::runtime_error("pressure averaging is not available in this build of the CUDA engine");
          if (impl->cell_volume.size() == 0)
            {
              impl->cell_volume.resize(impl->n_cell_sums());
              impl->cell_pressure_volume.resize(impl->n_cell_sums());
            }
          g = impl->view();
        }
      const long step_index = impl->steps_since_upload - 1;
      const bool timed      = impl->timed_from >= 0 && step_index >= impl->timed_from && impl->n_timed_steps < 5;
      impl->backend.enable_kernel_timing(timed);
      if (s.affine_state_variable >= 0 && impl->points.n_state_variables() < s.affine_state_variable + dim * dim)
        throw std::invalid_argument("DeviceEngine::step: the affine transfers need the points uploaded with their "
                                    "affine matrices (dim x dim state variables)");
      const bool all_physics =
        impl->all_laws || settings_need_all_physics(s) || shape_needs_all_physics(impl->shape);
      const StepReduction<Real> r =
        all_physics ? explicit_step<dim, DevicePhysics::all>(impl->backend, impl->shape, g, impl->points.view(),
                                                              impl->materials.data(), s, dt, impl->exchange,
                                                              &impl->averaging_pending) :
                      explicit_step<dim>(impl->backend, impl->shape, g, impl->points.view(), impl->materials.data(),
                                         s, dt, impl->exchange, &impl->averaging_pending);
      if (timed)
        {
          const std::vector<float> times = impl->backend.kernel_times_ms();
          impl->launch_ms.resize(std::max(impl->launch_ms.size(), times.size()), 0.0);
          for (size_t k = 0; k < times.size(); ++k)
            impl->launch_ms[k] += times[k];
          if (++impl->n_timed_steps == 5)
            {
              double total = 0;
              for (const double t : impl->launch_ms)
                total += t / 5;
              std::printf("  CUDA per-launch times, steps %ld-%ld, %d points (mean of 5 steps, sum %.3f ms):",
                          impl->timed_from, impl->timed_from + 4, impl->points.size(), total);
              for (size_t k = 0; k < impl->launch_ms.size(); ++k)
                std::printf(" %zu: %.3f", k, impl->launch_ms[k] / 5);
              std::printf("\n");
              std::fflush(stdout);
              impl->backend.enable_kernel_timing(false);
            }
        }
      return r;
    }
  } // namespace cuda
} // namespace mpm
