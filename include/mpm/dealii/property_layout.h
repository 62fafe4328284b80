// Where each field of the material points sits in a deal.II particle's property array, built
// from the fields the run's points carry (point_fields.h) and its models' state variables.
#pragma once

#include <mpm/core/host_storage.h>
#include <mpm/core/point_fields.h>

#include <deal.II/numerics/data_component_interpretation.h>

#include <string>
#include <vector>

namespace mpm
{
  // The points' properties in a particle's property array: the fields of point_fields.h that
  // live in the handler and that the run's points carry, in the list's order, then one per
  // state variable of the run's models (Parameters::state_variable_names).
  template <int dim>
  class PropertyLayout
  {
  public:
    explicit PropertyLayout(const PointFieldSet &fields = {}, const std::vector<std::string> &state_variable_names = {});

    // Where a carried field's first component sits.
    unsigned int offset(PointField field) const;
    unsigned int state_variables() const { return first_state_variable; }
    unsigned int n_properties() const { return first_state_variable + state_variable_names.size(); }

    // One name per property: a vector's name once per component, name_xx ... for Voigt and
    // tensor components, then the state variables' names.
    std::vector<std::string> names() const;
    // The field each property belongs to, as Output/Particle fields names it: "stress" for
    // stress_xx ... stress_xz, "strain" and "F" likewise, else the property's own name.
    std::vector<std::string> fields() const;
    std::vector<dealii::DataComponentInterpretation::DataComponentInterpretation> interpretations() const;

    // Point i's core fields (and state variables) into `values`, laid out as above; only those
    // the step writes if `written_only` (the rest stay as they are).
    void write(const HostPoints<dim, double> &points, int i, double *values, bool written_only = false) const;
    // And back: `values` into point i.
    void read(const double *values, HostPoints<dim, double> &points, int i) const;

    const PointFieldSet                carried;
    const std::vector<std::string>     state_variable_names;

  private:
    int          offsets[n_point_fields];
    unsigned int first_state_variable = 0;
  };

} // namespace mpm
