// Host-memory owners of point and grid arrays, handing out the views the step uses.
// The CUDA backend has device twins of these (backend/cuda_storage.h).
#pragma once

#include <mpm/core/boundary_masks.h>
#include <mpm/core/views.h>

#include <cstdint>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

namespace mpm
{
  // Whether an owner of point arrays holds state variables (HostPoints and the CUDA backend's
  // DevicePoints do: a user model's own on the CPU, the affine matrices and CPDI's corners on both).
  template <typename Storage, typename = void>
  struct has_state_variables : std::false_type
  {};
  template <typename Storage>
  struct has_state_variables<Storage, std::void_t<decltype(std::declval<Storage &>().state_variables)>>
    : std::true_type
  {};

  // The view of any owner of point arrays (HostPoints, the CUDA backend's DevicePoints):
  // the core fields of point_fields.h under their member names, arrays with .data(); null
  // for the fields the owner does not carry.
  template <int dim, typename Real, typename Storage>
  PointsView<dim, Real> make_points_view(Storage &s)
  {
    PointsView<dim, Real> v;
    v.n_points = s.size();
    for_each_core_field(v, s, [&](const PointField field, auto &view, auto &arrays) {
      if (s.fields.has(field))
        for_each_array_of(view, arrays, [](auto *&pointer, auto &array) { pointer = array.data(); });
    });
    if constexpr (has_state_variables<Storage>::value)
      {
        v.n_state_variables = static_cast<int>(s.state_variables.size());
        for (int k = 0; k < v.n_state_variables; ++k)
          v.state_variables[k] = s.state_variables[k].data();
      }
    return v;
  }

  // Visits the matching arrays of two owners of point arrays (HostPoints, DevicePoints,
  // or one owner twice) as f(array of a, array of b): upload, download, permutation,
  // checkpoints. The fields both carry (both must carry the same), then the state variables
  // where both hold them, a's count of them (b has as many).
  template <int dim, typename A, typename B, typename F>
  void for_each_point_array(A &a, B &b, F &&f)
  {
    for_each_core_field(a, b, [&](const PointField field, auto &arrays_a, auto &arrays_b) {
      if (a.fields.has(field) != b.fields.has(field))
        throw std::invalid_argument(std::string("for_each_point_array: the field '") + info(field).member +
                                    "' is carried by one owner of point arrays and not by the other (copy "
                                    "PointFieldSet fields before resizing an owner to be filled).");
      if (a.fields.has(field))
        for_each_array_of(arrays_a, arrays_b, f);
    });
    if constexpr (has_state_variables<std::decay_t<A>>::value && has_state_variables<std::decay_t<B>>::value)
      {
        if (b.state_variables.size() < a.state_variables.size())
          throw std::length_error("for_each_point_array: the second owner holds fewer state variables than the "
                                  "first (HostPoints::set_n_state_variables).");
        for (std::size_t k = 0; k < a.state_variables.size(); ++k)
          f(a.state_variables[k], b.state_variables[k]);
      }
  }

  // Point arrays in host memory: the core fields of point_fields.h that `fields` names (the
  // others stay empty), and the state variables.
  template <int dim, typename Real>
  struct HostPoints
  {
    template <typename T>
    using FieldArray = std::vector<T>;

    MPM_POINT_CORE_MEMBERS
    // The user models' state variables (PointsView::state_variables): one array per
    // variable, none unless a model of the run declares some.
    std::vector<std::vector<Real>> state_variables;
    // The fields these points carry (set before resize; carry() adds one later).
    PointFieldSet fields;

    int size() const { return static_cast<int>(mass.size()); } // mass: every run carries it
    int n_state_variables() const { return static_cast<int>(state_variables.size()); }

    // Holds n state variable arrays (of the current size); resize() keeps their number.
    void set_n_state_variables(const int count)
    {
      state_variables.resize(count);
      for (auto &array : state_variables)
        array.resize(mass.size());
    }

    // Carries `field` from now on, its new arrays at their initial value.
    void carry(const PointField field)
    {
      fields.insert(field);
      resize(size());
    }

    // n points: new ones at each field's initial value (zero; the identity for F).
    void resize(const int count)
    {
      for_each_core_field(*this, [&](const PointField field, auto &member) {
        if (!fields.has(field))
          return;
        int c = 0;
        for_each_array_of(member, [&](auto &array) {
          const bool diagonal = info(field).identity && c % (dim + 1) == 0;
          array.resize(count, diagonal ? 1 : 0);
          ++c;
        });
      });
      for (auto &array : state_variables)
        array.resize(count);
    }

    PointsView<dim, Real> view() { return make_points_view<dim, Real>(*this); }
  };

  // The view of any owner of grid arrays (HostGrid, the CUDA backend's DeviceGrid):
  // arrays with .data() and .size() under the member names of HostGrid. The cell arrays
  // of the pressure averaging are optional (empty: null in the view).
  template <int dim, typename Real, typename Storage>
  GridView<dim, Real> make_grid_view(Storage &s)
  {
    GridView<dim, Real> v;
    for (int d = 0; d < dim; ++d)
      {
        v.origin[d]   = s.origin[d];
        v.n_cells[d]  = s.n_cells[d];
        v.momentum[d] = s.momentum[d].data();
        v.force[d]    = s.force[d].data();
        v.velocity[d] = s.velocity[d].data();
      }
    v.h                = s.h;
    v.lattice_to_node  = s.lattice_to_node.size() > 0 ? s.lattice_to_node.data() : nullptr;
    v.box_is_lattice(); // where the owner has no lookup
    v.n_nodes          = static_cast<int>(s.mass.size());
    v.mass             = s.mass.data();
    v.fixed_components = s.fixed_components.data();
    if (s.friction_faces.size() > 0)
      {
        v.friction_faces = s.friction_faces.data();
        for (int f = 0; f < 2 * dim; ++f)
          v.friction_coefficient[f] = s.friction_coefficient[f];
      }
    if (s.cell_volume.size() > 0)
      {
        v.cell_volume          = s.cell_volume.data();
        v.cell_pressure_volume = s.cell_pressure_volume.data();
      }
    return v;
  }

  template <int dim, typename Real>
  struct HostGrid
  {
    Real                      origin[dim];
    Real                      h;
    int                       n_cells[dim];
    std::vector<int>          lattice_to_node;
    std::vector<int>          block_slot; // a block table instead (views.h); empty: none
    int                       block_cells      = 0;
    int                       node_blocks[dim] = {};
    std::vector<Real>         mass, momentum[dim], force[dim], velocity[dim];
    std::vector<std::uint8_t> fixed_components;
    std::vector<std::uint8_t> friction_faces;                    // empty: no frictional wall (views.h)
    Real                      friction_coefficient[2 * dim] = {}; // mu of each grid face
    FaceConditions<dim>       faces; // what each face of the lattice prescribes (the masks' source)
    std::vector<Real>         cell_volume, cell_pressure_volume; // pressure-averaging scratch, one per lattice cell

    // A dense grid whose node numbering is the lattice numbering (standalone use).
    void make_dense(const Real lower[dim], const Real cell_size, const int cells[dim])
    {
      h         = cell_size;
      long n    = 1;
      for (int d = 0; d < dim; ++d)
        {
          origin[d]  = lower[d];
          n_cells[d] = cells[d];
          n *= cells[d] + 1;
        }
      lattice_to_node.resize(n);
      for (long i = 0; i < n; ++i)
        lattice_to_node[i] = static_cast<int>(i);
      allocate_nodes(static_cast<int>(n));
      allocate_cells();
    }

    // Scratch of the cell pressure averaging, one entry per lattice cell.
    void allocate_cells()
    {
      long n = 1;
      for (int d = 0; d < dim; ++d)
        n *= n_cells[d];
      cell_volume.assign(n, Real(0));
      cell_pressure_volume.assign(n, Real(0));
    }

    void allocate_nodes(const int n_nodes)
    {
      mass.assign(n_nodes, Real(0));
      for (int d = 0; d < dim; ++d)
        {
          momentum[d].assign(n_nodes, Real(0));
          force[d].assign(n_nodes, Real(0));
          velocity[d].assign(n_nodes, Real(0));
        }
      fixed_components.assign(n_nodes, 0);
    }

    // Lattice coordinates of a lattice index (inverse of GridView::node's ordering).
    void lattice_coordinates(const long lattice, int idx[dim]) const
    {
      lattice_node_coordinates<dim>(n_cells, lattice, idx);
    }

    GridView<dim, Real> view()
    {
      GridView<dim, Real> v = make_grid_view<dim, Real>(*this);
      if (!block_slot.empty())
        v.set_block_table(block_slot.data(), block_cells, node_blocks);
      return v;
    }
  };
} // namespace mpm
