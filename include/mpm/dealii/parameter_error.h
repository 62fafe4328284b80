// The error of a bad prm entry, the same words everywhere: "Parameter 'Section/Entry': what".
#pragma once

#include <deal.II/base/exceptions.h>

#include <cstdlib>
#include <string>

namespace mpm
{
  // Throws the deal.II exception naming the entry (its full path) and what is wrong with it.
  [[noreturn]] inline void parameter_error(const std::string &entry, const std::string &what)
  {
    AssertThrow(false, dealii::ExcMessage("Parameter '" + entry + "': " + what));
    std::abort(); // not reached
  }
} // namespace mpm
