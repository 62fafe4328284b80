// Device twins of HostPoints / HostGrid (host_storage.h): the same arrays in device
// memory (cudaMalloc), filled by upload() from the host owners, copied back by
// download() only when the host must see them (output, tests), and handing out the
// same GridView / PointsView the step works on. Every CUDA call is checked.
//
// Include from .cu files only (needs nvcc) or from host code linked with cudart.
#pragma once

#include <mpm/core/backend/cuda_check.h>
#include <mpm/core/host_storage.h>
#include <mpm/core/material/material.h>

#include <cuda_runtime.h>

#include <cstddef>
#include <cstdint>
#include <utility>
#include <vector>

namespace mpm
{
  // An owning device array of trivially copyable T. Like std::vector it keeps its memory
  // when it shrinks, so that the arrays of points that change in number (migration between
  // ranks) are not freed and allocated again: cudaFree waits for the whole device.
  template <typename T>
  class DeviceArray
  {
  public:
    using value_type = T;
    DeviceArray() = default;
    explicit DeviceArray(const size_t n) { resize(n); }
    DeviceArray(const DeviceArray &)            = delete;
    DeviceArray &operator=(const DeviceArray &) = delete;
    DeviceArray(DeviceArray &&other) noexcept { swap(other); }
    DeviceArray &operator=(DeviceArray &&other) noexcept
    {
      swap(other);
      return *this;
    }
    ~DeviceArray() { cudaFree(ptr); } // no throwing from a destructor

    // New size; the contents are undefined unless it fits the memory held, which then
    // keeps them.
    void resize(const size_t new_size)
    {
      if (new_size <= capacity)
        {
          n = new_size;
          return;
        }
      if (ptr != nullptr)
        MPM_CUDA_CHECK(cudaFree(ptr));
      ptr      = nullptr;
      n        = new_size;
      capacity = new_size;
      MPM_CUDA_CHECK(cudaMalloc(&ptr, n * sizeof(T)));
    }

    // New size keeping the first min(old, new) entries. Beyond the memory held it takes
    // an eighth more than asked (points keep arriving by migration) and copies the old
    // entries over on `stream`.
    void resize_preserving(const size_t new_size, const cudaStream_t stream)
    {
      if (new_size <= capacity)
        {
          n = new_size;
          return;
        }
      DeviceArray longer;
      longer.resize(new_size + new_size / 8);
      longer.n = new_size;
      if (n > 0)
        MPM_CUDA_CHECK(cudaMemcpyAsync(longer.ptr, ptr, n * sizeof(T), cudaMemcpyDeviceToDevice, stream));
      swap(longer); // the old memory's cudaFree waits for the copy
    }

    void upload(const std::vector<T> &host)
    {
      resize(host.size());
      if (n > 0)
        MPM_CUDA_CHECK(cudaMemcpy(ptr, host.data(), n * sizeof(T), cudaMemcpyHostToDevice));
    }

    void download(std::vector<T> &host) const
    {
      host.resize(n);
      if (n > 0)
        MPM_CUDA_CHECK(cudaMemcpy(host.data(), ptr, n * sizeof(T), cudaMemcpyDeviceToHost));
    }

    // Every byte set to `byte` (poisoning in tests, zeroing).
    void fill_bytes(const int byte)
    {
      if (n > 0)
        MPM_CUDA_CHECK(cudaMemset(ptr, byte, n * sizeof(T)));
    }

    T      *data() { return ptr; }
    const T *data() const { return ptr; }
    size_t size() const { return n; }
    size_t bytes() const { return n * sizeof(T); }

    void swap(DeviceArray &other) noexcept
    {
      std::swap(ptr, other.ptr);
      std::swap(n, other.n);
      std::swap(capacity, other.capacity);
    }

  private:
    T     *ptr      = nullptr;
    size_t n        = 0;
    size_t capacity = 0;
  };

  // Point arrays in device memory: the fields of the uploaded points (point_fields.h).
  template <int dim, typename Real>
  struct DevicePoints
  {
    template <typename T>
    using FieldArray = DeviceArray<T>;

    MPM_POINT_CORE_MEMBERS
    // The affine transfers' matrices (StepSettings::affine_state_variable): as many arrays as
    // the uploaded points hold, none unless the run uses TPIC or APIC.
    std::vector<DeviceArray<Real>> state_variables;
    PointFieldSet                  fields; // those of the uploaded points

    int size() const { return static_cast<int>(mass.size()); }
    int n_state_variables() const { return static_cast<int>(state_variables.size()); }

    void upload(const HostPoints<dim, Real> &h)
    {
      fields = h.fields;
      state_variables.resize(h.state_variables.size());
      for_each_point_array<dim>(*this, h, [](auto &device, const auto &host) { device.upload(host); });
    }

    void download(HostPoints<dim, Real> &h) const
    {
      h.fields = fields;
      if (h.n_state_variables() < n_state_variables())
        h.set_n_state_variables(n_state_variables());
      for_each_point_array<dim>(*this, h, [](const auto &device, auto &host) { device.download(host); });
    }

    // Bytes of device memory held per point by the fields `carried`, without state variables.
    static constexpr size_t bytes_per_point(const PointFieldSet carried = {})
    {
      size_t bytes = 0;
      for (int f = 0; f < n_point_fields; ++f)
        if (point_field_info[f].place != FieldPlace::handler && carried.has(static_cast<PointField>(f)))
          bytes += field_arrays<dim>(point_field_info[f].shape) * (point_field_info[f].integer ? sizeof(int) : sizeof(Real));
      return bytes;
    }

    PointsView<dim, Real> view() { return make_points_view<dim, Real>(*this); }
  };

  template <int dim, typename Real>
  struct DeviceGrid
  {
    Real                      origin[dim];
    Real                      h = 0;
    int                       n_cells[dim];
    DeviceArray<int>          lattice_to_node;
    DeviceArray<int>          block_slot; // a block table instead (views.h), kept by the owner
    int                       block_cells      = 0;
    int                       node_blocks[dim] = {};
    DeviceArray<Real>         mass, momentum[dim], force[dim], velocity[dim];
    DeviceArray<std::uint8_t> fixed_components;
    DeviceArray<std::uint8_t> friction_faces; // empty: no frictional wall
    Real                      friction_coefficient[2 * dim] = {};
    DeviceArray<Real>         cell_volume, cell_pressure_volume; // pressure averaging; empty unless resized

    int n_nodes() const { return static_cast<int>(mass.size()); }

    // Geometry, lookup, masks and the current nodal values.
    void upload(const HostGrid<dim, Real> &g)
    {
      h = g.h;
      for (int d = 0; d < dim; ++d)
        {
          origin[d]  = g.origin[d];
          n_cells[d] = g.n_cells[d];
          momentum[d].upload(g.momentum[d]);
          force[d].upload(g.force[d]);
          velocity[d].upload(g.velocity[d]);
        }
      // No lookup where the host's is the identity, or where it has none (a box of the
      // lattice, which the owner sets with set_box; the whole lattice until then).
      lattice_order = g.lattice_to_node.empty() || g.lattice_to_node.size() == g.mass.size();
      for (size_t l = 0; !g.lattice_to_node.empty() && lattice_order && l < g.lattice_to_node.size(); ++l)
        lattice_order = g.lattice_to_node[l] == static_cast<int>(l);
      lattice_to_node.upload(lattice_order ? std::vector<int>() : g.lattice_to_node);
      by_blocks = false;
      for (int d = 0; d < dim; ++d)
        {
          box_lower[d] = 0;
          box_nodes[d] = n_cells[d] + 1;
        }
      mass.upload(g.mass);
      fixed_components.upload(g.fixed_components);
      friction_faces.upload(g.friction_faces);
      for (int f = 0; f < 2 * dim; ++f)
        friction_coefficient[f] = g.friction_coefficient[f];
    }

    // New nodes: n_nodes = fixed.size(), reached through the block table block_slot (views.h;
    // its entries set by the owner) of node blocks of `cells` nodes along each axis, with
    // those masks (friction empty: no frictional face) and every nodal value zero; the
    // geometry stays. The memory held only grows.
    void use_blocks(const int cells, const int blocks[dim], const std::vector<std::uint8_t> &fixed,
                    const std::vector<std::uint8_t> &friction)
    {
      reset_nodes(fixed.size());
      lattice_order = false;
      by_blocks     = true;
      lattice_to_node.resize(0);
      block_cells = cells;
      for (int d = 0; d < dim; ++d)
        node_blocks[d] = blocks[d];
      fixed_components.upload(fixed);
      friction_faces.upload(friction);
    }

    // New nodes: the box of lattice nodes lower[d] .. lower[d] + nodes[d] - 1, in lattice
    // order with no lookup, with those masks (one per box node; friction empty: no
    // frictional face) and every nodal value zero.
    void set_box(const int lower[dim], const int nodes[dim], const std::vector<std::uint8_t> &fixed,
                 const std::vector<std::uint8_t> &friction)
    {
      reset_nodes(fixed.size());
      set_box(lower, nodes);
      lattice_to_node.resize(0);
      fixed_components.upload(fixed);
      friction_faces.upload(friction);
    }

    // The numbering only: the nodes are that box of the lattice (the arrays the owner's).
    void set_box(const int lower[dim], const int nodes[dim])
    {
      lattice_order = true;
      by_blocks     = false;
      for (int d = 0; d < dim; ++d)
        {
          box_lower[d] = lower[d];
          box_nodes[d] = nodes[d];
        }
    }

    // n nodes, every nodal value zero.
    void reset_nodes(const size_t n)
    {
      mass.resize(n);
      for (int d = 0; d < dim; ++d)
        {
          momentum[d].resize(n);
          force[d].resize(n);
          velocity[d].resize(n);
          momentum[d].fill_bytes(0);
          force[d].fill_bytes(0);
          velocity[d].fill_bytes(0);
        }
      mass.fill_bytes(0);
    }

    // Nodal values back to the host (tests, output).
    void download_nodal(HostGrid<dim, Real> &g) const
    {
      for (int d = 0; d < dim; ++d)
        {
          momentum[d].download(g.momentum[d]);
          force[d].download(g.force[d]);
          velocity[d].download(g.velocity[d]);
        }
      mass.download(g.mass);
    }

    // Whether the nodes are a box of the lattice in lattice order (the view then has no
    // lookup), and that box.
    bool lattice_order = false;
    bool by_blocks     = false; // through block_slot
    int  box_lower[dim] = {};
    int  box_nodes[dim] = {};

    GridView<dim, Real> view()
    {
      GridView<dim, Real> v = make_grid_view<dim, Real>(*this);
      if (by_blocks)
        v.set_block_table(block_slot.data(), block_cells, node_blocks);
      if (lattice_order)
        {
          v.lattice_to_node = nullptr;
          for (int d = 0; d < dim; ++d)
            {
              v.box_lower[d] = box_lower[d];
              v.box_nodes[d] = box_nodes[d];
            }
        }
      return v;
    }
  };

  // The material table the constitutive update indexes by p.material[i].
  template <typename Real>
  struct DeviceMaterials
  {
    DeviceArray<MaterialParameters<Real>> table;

    void upload(const std::vector<MaterialParameters<Real>> &materials) { table.upload(materials); }
    const MaterialParameters<Real> *data() const { return table.data(); }
  };
} // namespace mpm
