// Solver/Method = auto's choice (method_choice.h) against doc/study.csv read here on its own:
// - at each of the study's resolutions and a range of tolerances, the pick's expected error is the
//   study's error of that method there and within the tolerance; where the choice refuses, no
//   method that ran stably at every resolution of that scene is within the tolerance there;
// - a looser tolerance never picks a method more than 10% costlier (costs within 10% count as equal);
// - below the study's coarsest resolution the error is the coarsest's scaled at first order;
// - Hencky's methods only where allowed, pure FLIP never in 3D.
#include <mpm/dealii/method_choice.h>

#include "../core/check.h"

#include <cmath>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <vector>

namespace
{
  struct Row
  {
    double cells, error; // error < 0: unstable
  };

  // scene kind -> method -> rows (CPU, FP64), as scripts/dev/method_table.py reads them.
  std::map<std::string, std::map<std::string, std::vector<Row>>> read_study(const std::string &file)
  {
    const std::map<std::string, std::pair<std::string, double>> scenes = {
      {"v3", {"run-out", 0.2}}, {"v1", {"compression", 10.0}}, {"v2", {"bending", 4.0}}, {"mms", {"large stretch", 1.0}}};
    std::map<std::string, std::map<std::string, std::vector<Row>>> study;
    std::ifstream in(file);
    std::string   line;
    std::getline(in, line); // header: scene,method,h,points,steps,wall_s,point_updates_per_s,error,stable,precision,backend,...
    while (std::getline(in, line))
      {
        std::vector<std::string> f;
        std::stringstream        s(line);
        std::string              field;
        for (int k = 0; k < 11 && std::getline(s, field, ','); ++k)
          f.push_back(field);
        if (f.size() < 11 || scenes.count(f[0]) == 0 || f[9] != "FP64" || f[10] != "cpu")
          continue;
        const auto &[kind, extent] = scenes.at(f[0]);
        const double error         = f[8] == "yes" && !f[7].empty() ? std::stod(f[7]) : -1;
        study[kind][f[1]].push_back({extent / std::stod(f[2]), error});
      }
    return study;
  }
} // namespace

int main()
{
  using namespace mpm;
  const auto study = read_study(std::string(MPM_SOURCE_DIR) + "/doc/study.csv");
  mpm_test::check(study.size() == 4, "the study has its four scenes");
  int picks = 0, refusals = 0;
  for (const auto &[scene, methods] : study)
    {
      std::set<double> resolutions;
      for (const auto &[name, rows] : methods)
        for (const Row &r : rows)
          resolutions.insert(r.cells);
      for (const double cells : resolutions)
        {
          double last_cost = 0;
          for (const double tolerance : {0.005, 0.01, 0.02, 0.05, 0.1, 0.3, 1.0})
            {
              // The most accurate method there among those stable at every resolution.
              double best = INFINITY;
              for (const auto &[name, rows] : methods)
                {
                  bool   stable = true;
                  double here   = INFINITY;
                  for (const Row &r : rows)
                    {
                      stable = stable && r.error >= 0;
                      if (std::abs(r.cells - cells) < 1e-9 * cells)
                        here = r.error;
                    }
                  if (stable)
                    best = std::min(best, here);
                }
              try
                {
                  const MethodChoice c = choose_method(scene, cells, tolerance, false, true, 2);
                  double             listed = -1;
                  for (const Row &r : methods.at(c.method.name))
                    if (std::abs(r.cells - cells) < 1e-9 * cells)
                      listed = r.error;
                  const std::string what = scene + " at " + std::to_string(cells) + " cells, tolerance " +
                                           std::to_string(tolerance) + ": " + c.method.name;
                  mpm_test::check(c.expected_error <= tolerance, (what + " is within the tolerance").c_str());
                  mpm_test::check(std::abs(c.expected_error - listed) <= 1e-5 * listed,
                                  (what + ": expected error is the study's").c_str());
                  if (last_cost > 0)
                    mpm_test::check(c.relative_cost <= 1.1 * last_cost * (1 + 1e-12),
                                    (what + ": a looser tolerance picks no costlier method").c_str());
                  last_cost = c.relative_cost;
                  ++picks;
                }
              catch (const std::invalid_argument &)
                {
                  mpm_test::check(!(best <= tolerance), (scene + ": refused only where no stable method is within "
                                                                 "the tolerance")
                                                          .c_str());
                  ++refusals;
                }
            }
        }
    }
  std::printf("%d picks and %d refusals checked against doc/study.csv\n", picks, refusals);
  mpm_test::check(picks > 20 && refusals > 0, "both outcomes occur");

  // Below the coarsest resolution: first-order growth from the coarsest row.
  {
    const MethodChoice c      = choose_method("large stretch", 4, 10.0, false, true, 2);
    double             coarse = -1;
    for (const Row &r : study.at("large stretch").at(c.method.name))
      if (r.cells == 8)
        coarse = r.error;
    std::printf("large stretch at 4 cells: %s, expected error %.4g (the study's at 8 cells: %.4g)\n",
                c.method.label.c_str(), c.expected_error, coarse);
    mpm_test::check(std::abs(c.expected_error - 2 * coarse) <= 1e-5 * coarse, "below the coarsest: scaled at first order");
  }
  // Restrictions: no Hencky where not allowed, no pure FLIP in 3D; the log names them.
  for (const double tolerance : {0.01, 0.02, 0.05, 0.1})
    for (const double cells : {16.0, 32.0, 64.0})
      for (const std::string scene : {"large stretch", "run-out", "compression"})
        try
          {
            const MethodChoice no_hencky = choose_method(scene, cells, tolerance, false, false, 2);
            mpm_test::check(!no_hencky.method.hencky, "Hencky only where allowed");
            const MethodChoice in_3d = choose_method(scene, cells, tolerance, false, true, 3);
            mpm_test::check(!(in_3d.method.flip_fraction == 1 && !in_3d.method.affine), "no pure FLIP in 3D");
            mpm_test::check(in_3d.reason.find("uGIMP, pure FLIP: unstable on P2") != std::string::npos,
                            "the log says why pure FLIP is left out in 3D");
          }
        catch (const std::invalid_argument &)
          {}
  return mpm_test::finish("test_method_choice");
}
