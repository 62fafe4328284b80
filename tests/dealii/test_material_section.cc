// A built-in member's prm section, declared by the core model (material_entries.h) and turned
// into ParameterHandler entries by the library (material_library.cc), through the material
// family's test member (J2 plasticity, include/mpm/core/material/models/test_von_mises_model.h):
//  - a member owned by `test` is not in the prm until register_test_materials(): before it,
//    it is not among the Model names and Model = test von mises is refused;
//  - its entries reach the core: the parsed yield stress is the prm's; a yield stress of 0 is
//    refused naming Material <name>/test von mises/Yield stress; an unknown entry in its section
//    is refused;
//  - the reduced 2D collapse with the member (CPU backend, 60 steps): with a yield stress
//    above every stress of the scene its points equal the linear elastic run's to the last bit
//    (the member's elastic path is Hooke's law); with 1.5 kPa the points yield, and every
//    point's von Mises stress q = sqrt(3 J2) stays within round-off of sigma_y.
#include "../core/check.h"

#include <mpm/dealii/material_library.h>
#include <mpm/dealii/parameters.h>
#include <mpm/dealii/simulator.h>

#include <deal.II/base/mpi.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>

using namespace mpm;
using mpm_test::check;
using mpm_test::throws_naming;

namespace
{
  // tests/prm/collapse_small_2d.prm with `section` as its material's model and subsection.
  std::string scene_text(const std::string &section, const int max_steps = 60)
  {
    std::ifstream     in(std::string(MPM_SOURCE_DIR) + "/tests/prm/collapse_small_2d.prm");
    std::stringstream s;
    s << in.rdbuf();
    std::string       text  = s.str();
    const std::size_t begin = text.find("  set Model = drucker prager");
    const std::size_t end   = text.find("  end\n", begin) + 6;
    text.replace(begin, end - begin, section);
    return text + "\nsubsection Solver\n set Maximum number of steps = " + std::to_string(max_steps) + "\nend\n"
                  "subsection Output\n set Output interval = 0\n set Write particles = false\n"
                  " set Write grid fields = false\nend\n";
  }

  std::string von_mises(const std::string &yield_stress, const std::string &extra = "")
  {
    return "  set Model = test von mises\n  subsection test von mises\n    set Young's modulus = 0.84e6\n"
           "    set Poisson's ratio = 0.3\n    set Yield stress = " +
           yield_stress + "\n" + extra + "  end\n";
  }

  const std::string linear_elastic = "  set Model = linear elastic\n  subsection linear elastic\n"
                                     "    set Young's modulus = 0.84e6\n    set Poisson's ratio = 0.3\n  end\n";

  HostPoints<2, double> run(const std::string &text)
  {
    Simulator<2> simulator(parameters_from_string(text), MPI_COMM_WORLD);
    simulator.run();
    return simulator.points();
  }

  // Largest |a - b| over positions, stresses and plastic strains; 1e300 where the sizes differ.
  double difference(const HostPoints<2, double> &a, const HostPoints<2, double> &b)
  {
    double worst = a.size() == b.size() ? 0 : 1e300;
    for (int i = 0; worst < 1e300 && i < a.size(); ++i)
      {
        for (int d = 0; d < 2; ++d)
          worst = std::max(worst, std::abs(a.position[d][i] - b.position[d][i]));
        for (int c = 0; c < n_voigt; ++c)
          worst = std::max(worst, std::abs(a.stress[c][i] - b.stress[c][i]));
        worst = std::max(worst, std::abs(a.plastic_strain[i] - b.plastic_strain[i]));
      }
    return worst;
  }
} // namespace

int main(int argc, char **argv)
{
  dealii::Utilities::MPI::MPI_InitFinalize mpi(argc, argv, 1);
  try
    {
      check(material_model_names().find("test von mises") == std::string::npos &&
              throws_naming([]() { parameters_from_string(scene_text(von_mises("2e3"))); }, "does not match"),
            "a test member is not in the prm before register_test_materials()");
      register_test_materials();
      register_test_materials(); // a second call does nothing
      check(material_model_names().find("test von mises") != std::string::npos, "registered, the member is a Model");

      const Parameters p = parameters_from_string(scene_text(von_mises("2e3")));
      check(p.materials.size() == 1 && p.materials[0].model == MaterialModel::test_von_mises &&
              p.materials[0].test_von_mises.yield_stress == 2e3 && p.materials[0].elastic.youngs_modulus == 0.84e6,
            "the member's entries reach the core's parameters");
      check(throws_naming([]() { parameters_from_string(scene_text(von_mises("0"))); },
                          "Material aluminium bars/test von mises/Yield stress"),
            "a yield stress of 0 is refused, naming the entry");
      check(throws_naming([]() { parameters_from_string(scene_text(von_mises("2e3", "    set Cohesion = 1\n"))); },
                          "Cohesion"),
            "an entry the member does not declare is refused");

      const HostPoints<2, double> elastic = run(scene_text(linear_elastic));
      const HostPoints<2, double> stiff   = run(scene_text(von_mises("1e30")));
      const double                same    = difference(elastic, stiff);
      std::printf("test von Mises with sigma_y = 1e30 against linear elastic, 60 steps: largest difference %.3e\n",
                  same);
      check(same == 0, "below yield the member's run equals the linear elastic run to the last bit");

      const double                sigma_y = 1.5e3;
      const HostPoints<2, double> flow    = run(scene_text(von_mises("1.5e3")));
      double                      q_max = 0, eps_p_max = 0;
      for (int i = 0; i < flow.size(); ++i)
        {
          const double mean = (flow.stress[0][i] + flow.stress[1][i] + flow.stress[2][i]) / 3;
          double       j2   = 0;
          for (int c = 0; c < n_voigt; ++c)
            {
              const double s = c < 3 ? flow.stress[c][i] - mean : flow.stress[c][i];
              j2 += (c < 3 ? 0.5 : 1.0) * s * s;
            }
          q_max     = std::max(q_max, std::sqrt(3 * j2));
          eps_p_max = std::max(eps_p_max, flow.plastic_strain[i]);
        }
      std::printf("test von Mises with sigma_y = 1.5 kPa, 60 steps: largest q %.6e Pa, largest eps_p %.3e\n", q_max,
                  eps_p_max);
      check(eps_p_max > 1e-5, "the points yield", eps_p_max, 1e-5);
      check(q_max <= sigma_y * (1 + 1e-12), "every point's q stays on or inside the yield surface", q_max, sigma_y);
      check(q_max > sigma_y * (1 - 1e-9), "points reach the yield surface", q_max, sigma_y);
    }
  catch (const std::exception &e)
    {
      std::printf("exception: %s\n", e.what());
      return 1;
    }
  return mpm_test::finish("test_material_section");
}
