// What a Backend offers beyond its loops: colouring scatters (the CPU's), atomic adds (the
// device's), per-point scratch memory. Detected from the backend's members.
// Part of the explicit step (step.h); header-only, host and device.
#pragma once

#include <cmath>
#include <mpm/core/cubic_bspline_gimp.h>
#include <mpm/core/domain_update.h>
#include <mpm/core/interpolation.h>
#include <mpm/core/local_damping.h>
#include <mpm/core/material/material.h>
#include <mpm/core/prefetch.h>
#include <mpm/core/shape_functions.h>
#include <mpm/core/small_tensor.h>
#include <mpm/core/stencil_contribution.h>
#include <mpm/core/views.h>
#include <mpm/core/wall_friction.h>
#include <stdexcept>
#include <type_traits>
#include <utility>

#include <cmath>
#include <stdexcept>
#include <type_traits>
#include <utility>

namespace mpm
{
  // Backends whose scatters run in parallel by colouring (CpuBackend) declare
  // `static constexpr bool colours_scatter = true` and group the points first.
  template <typename Backend, typename = void>
  struct colours_scatter : std::false_type
  {};

  template <typename Backend>
  struct colours_scatter<Backend, std::void_t<decltype(Backend::colours_scatter)>>
    : std::bool_constant<Backend::colours_scatter>
  {};

  // Backends whose add_to_node is atomic, so that a gather loop may also scatter into
  // cells (CudaBackend); the others scatter only inside scatter_points.
  template <typename Backend, typename = void>
  struct atomic_scatter : std::false_type
  {};

  template <typename Backend>
  struct atomic_scatter<Backend, std::void_t<decltype(Backend::atomic_scatter)>>
    : std::bool_constant<Backend::atomic_scatter>
  {};

  // Host backends that lend per-point scratch memory kept between steps
  // (CpuBackend::point_scratch(n, bytes per point)).
  template <typename Backend, typename = void>
  struct has_point_scratch : std::false_type
  {};

  template <typename Backend>
  struct has_point_scratch<Backend, std::void_t<decltype(std::declval<Backend &>().point_scratch(0, 0))>>
    : std::true_type
  {};
} // namespace mpm
