// A constitutive model registered from outside the library (material_library.h,
// user_model.h), through the whole run:
//  - a user model that is the core's Drucker-Prager behind the virtual interface, selected by
//    its name in the prm, gives the points of the built-in "drucker prager" to the last bit
//    after 60 steps of the reduced 2D collapse (plastic flow from the first steps): the update,
//    its state and the plasticity switch reach the user's code unchanged;
//  - refused with a message naming the entry: Backend = cuda with a user model, a random
//    field on a user model; a name registered twice is refused too.
#include "../core/check.h"

#include <mpm/core/material/drucker_prager.h>
#include <mpm/dealii/material_library.h>
#include <mpm/dealii/parameters.h>
#include <mpm/dealii/simulator.h>
#include <mpm/dealii/strength_parameters.h>

#include <deal.II/base/mpi.h>

#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>

using namespace mpm;
using mpm_test::check;
using mpm_test::throws_naming;

namespace
{
  class WrappedDruckerPrager : public UserConstitutiveModel
  {
  public:
    static void declare_parameters(dealii::ParameterHandler &prm)
    {
      declare_elastic_parameters(prm);
      declare_strength_parameters(prm);
    }
    void parse_parameters(dealii::ParameterHandler &prm)
    {
      elastic                   = parse_elastic_parameters(prm);
      model.strength            = parse_strength_parameters(prm);
      model.tensile_strength    = 1e30;
    }
    LinearElasticParameters<double> elastic_parameters() const override { return elastic; }
    void update_stress(const SymTensor<double> &d_eps, const Mat3<double> &d_spin, const bool plastic,
                       SymTensor<double> &stress, double &plastic_strain, double *) const override
    {
      drucker_prager_update(elastic, model, plastic, d_eps, d_spin, stress, plastic_strain);
    }

  private:
    LinearElasticParameters<double> elastic{};
    DruckerPragerParameters<double> model{};
  };
} // namespace

MPM_REGISTER_CONSTITUTIVE_MODEL(WrappedDruckerPrager, "wrapped drucker prager",
                                "The core's Drucker-Prager behind the user-model interface (a test).");

namespace
{
  std::string scene_text(const std::string &model, const std::string &extra = "")
  {
    std::ifstream     in(std::string(MPM_SOURCE_DIR) + "/tests/prm/collapse_small_2d.prm");
    std::stringstream s;
    s << in.rdbuf();
    std::string text = s.str();
    for (const std::string from : {"set Model = drucker prager", "subsection drucker prager"})
      {
        std::string to = from;
        to.replace(to.find("drucker prager"), 14, model);
        text.replace(text.find(from), from.size(), to);
      }
    return text + "\nsubsection Solver\n set Maximum number of steps = 60\nend\n"
                  "subsection Output\n set Output interval = 0\n set Write particles = false\n"
                  " set Write grid fields = false\nend\n" +
           extra;
  }

  HostPoints<2, double> run(const std::string &text)
  {
    Simulator<2> simulator(parameters_from_string(text), MPI_COMM_WORLD);
    simulator.run();
    return simulator.points();
  }

} // namespace

int main(int argc, char **argv)
{
  dealii::Utilities::MPI::MPI_InitFinalize mpi(argc, argv, 1);
  try
    {
      const HostPoints<2, double> built_in = run(scene_text("drucker prager"));
      const HostPoints<2, double> user     = run(scene_text("wrapped drucker prager"));
      double worst = built_in.size() == user.size() ? 0 : 1e300, plastic = 0;
      for (int i = 0; i < built_in.size() && i < user.size(); ++i)
        {
          for (int d = 0; d < 2; ++d)
            worst = std::max(worst, std::abs(built_in.position[d][i] - user.position[d][i]));
          for (int c = 0; c < n_voigt; ++c)
            worst = std::max(worst, std::abs(built_in.stress[c][i] - user.stress[c][i]));
          worst   = std::max(worst, std::abs(built_in.plastic_strain[i] - user.plastic_strain[i]));
          plastic = std::max(plastic, user.plastic_strain[i]);
        }
      std::printf("built-in and user Drucker-Prager after 60 steps: largest difference %.3e "
                  "(positions, stresses, eps_p); largest eps_p %.3e\n",
                  worst, plastic);
      check(plastic > 1e-4, "the scene flows plastically in its first 60 steps", plastic, 1e-4);
      check(worst == 0, "the user model's run equals the built-in model's to the last bit");

      check(throws_naming([]() { parameters_from_string(scene_text("wrapped drucker prager",
                                                                    "subsection Backend\n set Backend = cuda\nend\n")); },
                          "Backend/Backend"),
            "Backend = cuda with a user model is refused, naming the entry");
      check(throws_naming(
              []() {
                parameters_from_string(scene_text("wrapped drucker prager",
                                                  "subsection Material aluminium bars\n subsection Random field\n"
                                                  "  set Parameter = cohesion\n end\nend\n"));
              },
              "Random field/Parameter"),
            "a random field on a user model is refused, naming the entry");
      check(throws_naming([]() { register_material("drucker prager", material_library().at("drucker prager")); },
                          "registered twice"),
            "a name registered twice is refused");
    }
  catch (const std::exception &e)
    {
      std::printf("exception: %s\n", e.what());
      return 1;
    }
  return mpm_test::finish("test_user_model");
}
