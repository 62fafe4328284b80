// The manufactured solution (manufactured_solution.h) per method and resolution, for
// scripts/validation/study.py's scene "mms": one CSV row per run on standard output. Not a test
// (test_manufactured_solution asserts the rates); the wall time is the steps' alone.
//   mms_study [--methods a,b,...] [--cells 8,16,32] [--cfl 0.2] [--periods 1] [--precision 64|32]
// --precision 32: the step in float (the motion, the body force and the errors in double).
#include "manufactured_solution.h"

#include <cstdio>
#include <cstdlib>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

namespace
{
  std::vector<std::string> split(const std::string &list)
  {
    std::vector<std::string> items;
    std::stringstream        in(list);
    for (std::string item; std::getline(in, item, ',');)
      if (!item.empty())
        items.push_back(item);
    return items;
  }

  int usage(const std::string &why)
  {
    std::cerr << "mms_study: " << why
              << "\nusage: mms_study [--methods a,b,...] [--cells 8,16,32] [--cfl 0.2] [--periods 1] [--precision 64|32]\n";
    return 2;
  }
} // namespace

int main(int argc, char **argv)
{
  std::vector<std::string> methods;
  for (const auto &m : mpm_test::mms_methods())
    methods.push_back(m.key);
  std::vector<int> cells{8, 16, 32, 64};
  double           cfl = 0.2, periods = 1;
  int              precision = 64;
  try
    {
      for (int k = 1; k < argc; ++k)
        {
          const std::string arg = argv[k];
          if (k + 1 >= argc)
            return usage("'" + arg + "' needs a value");
          const std::string value = argv[++k];
          if (arg == "--methods")
            methods = split(value);
          else if (arg == "--cells")
            {
              cells.clear();
              for (const auto &c : split(value))
                cells.push_back(std::stoi(c));
            }
          else if (arg == "--cfl")
            cfl = std::stod(value);
          else if (arg == "--periods")
            periods = std::stod(value);
          else if (arg == "--precision")
            {
              if (value != "64" && value != "32")
                return usage("--precision must be 64 or 32, not '" + value + "'");
              precision = std::stoi(value);
            }
          else
            return usage("unknown option '" + arg + "'");
        }
      for (const int n : cells)
        if (n < 2)
          return usage("--cells: each count must be at least 2");
      if (!(cfl > 0 && cfl <= 1))
        return usage("--cfl must lie in (0, 1]");
      if (!(periods > 0))
        return usage("--periods must be positive");
      for (const auto &m : methods)
        mpm_test::mms_method(m); // unknown names fail before any run
    }
  catch (const std::exception &e)
    {
      return usage(e.what());
    }

  const mpm_test::AxisAlignedMotion base;
  std::printf("method,precision,cells,h,points,steps,wall_s,point_updates_per_s,displacement_error,stress_error,"
              "stable\n");
  for (const auto &key : methods)
    for (const int n : cells)
      {
        const auto method = mpm_test::mms_method(key);
        auto       motion = base;
        motion.law        = method.law;
        const auto r      = precision == 32 ?
                              mpm_test::run_manufactured_solution<float>(motion, method, n, cfl, periods) :
                              mpm_test::run_manufactured_solution<double>(motion, method, n, cfl, periods);
        std::printf("%s,FP%d,%d,%.6g,%ld,%ld,%.4f,%.4g,%.6e,%.6e,%s\n", key.c_str(), precision, n, motion.length / n,
                    r.n_points,
                    r.n_steps, r.wall_s, r.wall_s > 0 ? double(r.n_points) * r.n_steps / r.wall_s : 0.0,
                    r.displacement_error, r.stress_error, r.stable ? "yes" : "no");
        std::fflush(stdout);
      }
  return 0;
}
