// Small pieces every settings component reads its prm entries with: points as lists of numbers,
// their defaults and pattern, lists joined for messages.
#pragma once

#include <deal.II/base/parameter_handler.h>

#include <string>
#include <vector>

namespace mpm
{
  namespace prm_reading
  {
    extern const char *const axis_names[3]; // x, y, z

    // "0, 0, last": a point's default with its last coordinate set.
    std::string zeros(unsigned int dim, double last = 0);
    std::string ones(unsigned int dim);
    dealii::Patterns::List point_pattern(unsigned int dim);

    // The numbers of a list entry. The pattern has checked their form, but not their range: a
    // value such as 1e-400 matches Patterns::Double and still does not convert (refused naming
    // `entry`).
    std::vector<double> to_doubles(const std::string &entry, const std::string &text);
    // where: the subsection path of the entry, for the message.
    std::vector<double> get_point(dealii::ParameterHandler &prm, const std::string &entry, const std::string &where);
    // "a, b, c"
    std::string join(const std::vector<std::string> &items);
    // "a, b or c", "a, b and c"
    std::string join_or(const std::vector<std::string> &items);
    std::string join_and(const std::vector<std::string> &items);
  } // namespace prm_reading
} // namespace mpm
