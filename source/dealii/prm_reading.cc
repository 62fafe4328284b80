#include <mpm/dealii/parameter_error.h>
#include <mpm/dealii/prm_reading.h>

#include <deal.II/base/utilities.h>

namespace mpm
{
  namespace prm_reading
  {
    namespace Patterns = dealii::Patterns;
    using dealii::ParameterHandler;

    const char *const axis_names[3] = {"x", "y", "z"};

    std::string zeros(const unsigned int dim, const double last)
    {
      std::string s;
      for (unsigned int d = 0; d < dim; ++d)
        s += (d ? ", " : "") + dealii::Utilities::to_string(d + 1 == dim ? last : 0.0);
      return s;
    }

    std::string ones(const unsigned int dim)
    {
      std::string s;
      for (unsigned int d = 0; d < dim; ++d)
        s += d ? ", 1" : "1";
      return s;
    }

    Patterns::List point_pattern(const unsigned int dim)
    {
      return Patterns::List(Patterns::Double(), dim, dim, ",");
    }

    std::vector<double> to_doubles(const std::string &entry, const std::string &text)
    {
      std::vector<double> values;
      for (const std::string &item : dealii::Utilities::split_string_list(text, ','))
        {
          try
            {
              values.push_back(dealii::Utilities::string_to_double(item));
            }
          catch (...)
            {
              parameter_error(entry, "'" + item + "' is not a finite double-precision number (magnitudes from about "
                          "2.2e-308 to 1.8e308, or 0).");
            }
        }
      return values;
    }

    std::vector<double> get_point(ParameterHandler &prm, const std::string &entry, const std::string &where)
    {
      return to_doubles(where + entry, prm.get(entry));
    }

    std::string join(const std::vector<std::string> &items)
    {
      std::string s;
      for (const std::string &item : items)
        s += (s.empty() ? "" : ", ") + item;
      return s;
    }

    namespace
    {
      std::string join_with_last(const std::vector<std::string> &items, const std::string &last)
      {
        std::string s;
        for (std::size_t k = 0; k < items.size(); ++k)
          s += (k == 0 ? "" : (k + 1 == items.size() ? last : ", ")) + items[k];
        return s;
      }
    } // namespace

    std::string join_or(const std::vector<std::string> &items)
    {
      return join_with_last(items, " or ");
    }

    std::string join_and(const std::vector<std::string> &items)
    {
      return join_with_last(items, " and ");
    }
  } // namespace prm_reading
} // namespace mpm
