#include <mpm/dealii/property_layout.h>

#include <deal.II/base/exceptions.h>

#include <type_traits>

namespace mpm
{
  namespace
  {
    // The components' suffixes of a field of this shape ("" for scalars and vectors).
    template <int dim>
    std::vector<std::string> component_suffixes(const FieldShape shape)
    {
      const char *axis[3]  = {"x", "y", "z"};
      const char *voigt[6] = {"xx", "yy", "zz", "xy", "yz", "xz"};
      std::vector<std::string> s;
      switch (shape)
        {
          case FieldShape::scalar:
            return {""};
          case FieldShape::vector:
            return std::vector<std::string>(dim, "");
          case FieldShape::voigt:
            for (const char *c : voigt)
              s.push_back(std::string("_") + c);
            return s;
          case FieldShape::tensor:
            for (int a = 0; a < dim; ++a)
              for (int b = 0; b < dim; ++b)
                s.push_back(std::string("_") + axis[a] + axis[b]);
            return s;
        }
      return s;
    }

    bool in_handler(const PointField field, const PointFieldSet &carried)
    {
      return info(field).place != FieldPlace::core && carried.has(field);
    }
  } // namespace

  template <int dim>
  PropertyLayout<dim>::PropertyLayout(const PointFieldSet &fields, const std::vector<std::string> &state_variable_names)
    : carried(fields)
    , state_variable_names(state_variable_names)
  {
    unsigned int at = 0;
    for (int f = 0; f < n_point_fields; ++f)
      {
        const PointField field = static_cast<PointField>(f);
        offsets[f]             = in_handler(field, carried) ? static_cast<int>(at) : -1;
        if (offsets[f] >= 0)
          at += field_arrays<dim>(info(field).shape);
      }
    first_state_variable = at;
  }

  template <int dim>
  unsigned int PropertyLayout<dim>::offset(const PointField field) const
  {
    AssertThrow(offsets[static_cast<int>(field)] >= 0,
                dealii::ExcMessage(std::string("PropertyLayout: the points carry no property '") + info(field).member +
                                   "'."));
    return offsets[static_cast<int>(field)];
  }

  template <int dim>
  std::vector<std::string> PropertyLayout<dim>::names() const
  {
    std::vector<std::string> n;
    for (int f = 0; f < n_point_fields; ++f)
      if (offsets[f] >= 0)
        for (const std::string &suffix : component_suffixes<dim>(point_field_info[f].shape))
          n.push_back(point_field_info[f].output_name + suffix);
    n.insert(n.end(), state_variable_names.begin(), state_variable_names.end());
    return n;
  }

  template <int dim>
  std::vector<std::string> PropertyLayout<dim>::fields() const
  {
    std::vector<std::string> n;
    for (int f = 0; f < n_point_fields; ++f)
      if (offsets[f] >= 0)
        for (unsigned int c = 0; c < component_suffixes<dim>(point_field_info[f].shape).size(); ++c)
          n.push_back(point_field_info[f].output_name);
    n.insert(n.end(), state_variable_names.begin(), state_variable_names.end());
    return n;
  }

  template <int dim>
  std::vector<dealii::DataComponentInterpretation::DataComponentInterpretation>
  PropertyLayout<dim>::interpretations() const
  {
    using namespace dealii::DataComponentInterpretation;
    std::vector<DataComponentInterpretation> k;
    for (int f = 0; f < n_point_fields; ++f)
      if (offsets[f] >= 0)
        k.insert(k.end(), field_arrays<dim>(point_field_info[f].shape),
                 point_field_info[f].shape == FieldShape::vector ? component_is_part_of_vector : component_is_scalar);
    k.insert(k.end(), state_variable_names.size(), component_is_scalar);
    return k;
  }

  template <int dim>
  void PropertyLayout<dim>::write(const HostPoints<dim, double> &points, const int i, double *values,
                                  const bool written_only) const
  {
    for_each_core_field(points, [&](const PointField field, const auto &member) {
      const int at = offsets[static_cast<int>(field)];
      if (at < 0 || (written_only && !info(field).written_by_step))
        return;
      int c = 0;
      for_each_array_of(member, [&](const auto &array) { values[at + c++] = array[i]; });
    });
    for (int k = 0; k < points.n_state_variables(); ++k)
      values[first_state_variable + k] = points.state_variables[k][i];
  }

  template <int dim>
  void PropertyLayout<dim>::read(const double *values, HostPoints<dim, double> &points, const int i) const
  {
    for_each_core_field(points, [&](const PointField field, auto &member) {
      const int at = offsets[static_cast<int>(field)];
      if (at < 0)
        return;
      int c = 0;
      for_each_array_of(member, [&](auto &array) {
        using T  = typename std::decay_t<decltype(array)>::value_type;
        array[i] = static_cast<T>(values[at + c++]);
      });
    });
    for (int k = 0; k < points.n_state_variables(); ++k)
      points.state_variables[k][i] = values[first_state_variable + k];
  }

  template class PropertyLayout<2>;
  template class PropertyLayout<3>;
} // namespace mpm
