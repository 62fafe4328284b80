// Copies of the core's host-side structures in another floating-point type: a run whose
// step is in float (Backend/Precision) keeps its points and nodes in float and takes its
// settings and materials, given in double, through these. Plain aggregates, copied field
// by field; the sizes asserted below catch a field added to one of them and not here.
#pragma once

#include <mpm/core/host_storage.h>
#include <mpm/core/material/material.h>
#include <mpm/core/step/settings.h>

namespace mpm
{
  template <typename To, typename From>
  MaterialParameters<To> converted(const MaterialParameters<From> &m)
  {
    static_assert(sizeof(LinearElasticParameters<From>) == 2 * sizeof(From), "a field of the elastic part is not copied");
    MaterialParameters<To> r;
    r.model                           = m.model;
    r.elastic.youngs_modulus          = static_cast<To>(m.elastic.youngs_modulus);
    r.elastic.poissons_ratio          = static_cast<To>(m.elastic.poissons_ratio);
#define MPM_MATERIAL_CONVERTED(identifier, Member) \
    r.identifier = Member::template converted<To>(m.identifier);
    MPM_BUILT_IN_MATERIALS(MPM_MATERIAL_CONVERTED)
#undef MPM_MATERIAL_CONVERTED
    r.plasticity_enabled              = m.plasticity_enabled;
    r.field_parameter                 = m.field_parameter;
    r.elastic_law                     = m.elastic_law;
    r.disconnection_volume_ratio      = static_cast<To>(m.disconnection_volume_ratio);
    r.user_model                      = m.user_model; // runs in double only (the caller refuses float)
    return r;
  }

  template <typename To, typename From>
  std::vector<MaterialParameters<To>> converted(const std::vector<MaterialParameters<From>> &materials)
  {
    std::vector<MaterialParameters<To>> r;
    for (const MaterialParameters<From> &m : materials)
      r.push_back(converted<To>(m));
    return r;
  }

  // StepSettings: a field added there goes here too (the size asserted is today's, x86-64).
  template <typename To, int dim, typename From>
  StepSettings<dim, To> converted(const StepSettings<dim, From> &s)
  {
    static_assert(sizeof(StepSettings<3, double>) == 112, "a field of StepSettings is not copied here");
    StepSettings<dim, To> r;
    r.scheme = s.scheme;
    for (int d = 0; d < dim; ++d)
      r.gravity[d] = static_cast<To>(s.gravity[d]);
    r.damping                   = static_cast<To>(s.damping);
    r.damping_form              = s.damping_form;
    r.damping_threshold         = static_cast<To>(s.damping_threshold);
    r.flip_fraction             = static_cast<To>(s.flip_fraction);
    r.flip_fixed_velocity_change = s.flip_fixed_velocity_change;
    r.domain_update             = s.domain_update;
    r.mass_tolerance            = static_cast<To>(s.mass_tolerance);
    r.pressure_averaging        = s.pressure_averaging;
    r.disconnected_points       = s.disconnected_points;
    r.hold_points               = s.hold_points;
    r.hold_from_point_momentum  = s.hold_from_point_momentum;
    r.affine_state_variable     = s.affine_state_variable;
    r.affine_matrix             = s.affine_matrix;
    r.body_force_state_variable = s.body_force_state_variable;
    r.corner_state_variable     = s.corner_state_variable;
    r.wall_faces                = s.wall_faces;
    r.time_step_on_device       = nullptr; // a device's own, in its own precision (step.h)
    return r;
  }

  template <typename To, typename From>
  StepReduction<To> converted(const StepReduction<From> &s)
  {
    return {static_cast<To>(s.max_speed), static_cast<To>(s.gravity_power), static_cast<To>(s.max_removed_speed)};
  }

  // Every point array, rounded to To (or widened).
  template <typename To, int dim, typename From>
  void convert_points(const HostPoints<dim, From> &from, HostPoints<dim, To> &to)
  {
    to.state_variables.clear();
    to.fields = from.fields;
    to.resize(from.size());
    to.set_n_state_variables(from.n_state_variables());
    for_each_point_array<dim>(from, to, [](const auto &a, auto &b) { b.assign(a.begin(), a.end()); });
  }

  // A grid: geometry, numbering, boundary masks and nodal arrays.
  template <typename To, int dim, typename From>
  HostGrid<dim, To> converted(const HostGrid<dim, From> &g)
  {
    HostGrid<dim, To> r;
    for (int d = 0; d < dim; ++d)
      {
        r.origin[d]     = static_cast<To>(g.origin[d]);
        r.n_cells[d]    = g.n_cells[d];
        r.node_blocks[d] = g.node_blocks[d];
        r.momentum[d].assign(g.momentum[d].begin(), g.momentum[d].end());
        r.force[d].assign(g.force[d].begin(), g.force[d].end());
        r.velocity[d].assign(g.velocity[d].begin(), g.velocity[d].end());
      }
    r.h               = static_cast<To>(g.h);
    r.lattice_to_node = g.lattice_to_node;
    r.block_slot      = g.block_slot;
    r.block_cells     = g.block_cells;
    r.mass.assign(g.mass.begin(), g.mass.end());
    r.fixed_components = g.fixed_components;
    r.friction_faces   = g.friction_faces;
    for (int f = 0; f < 2 * dim; ++f)
      r.friction_coefficient[f] = static_cast<To>(g.friction_coefficient[f]);
    r.faces = g.faces;
    r.cell_volume.assign(g.cell_volume.begin(), g.cell_volume.end());
    r.cell_pressure_volume.assign(g.cell_pressure_volume.begin(), g.cell_pressure_volume.end());
    return r;
  }
} // namespace mpm
