// A constitutive model registered from outside the library (material_library.h,
// user_model.h), through the whole run:
//  - a user model that is the core's Drucker-Prager behind the virtual interface, selected by
//    its name in the prm, gives the points of the built-in "drucker prager" to the last bit
//    after 60 steps of the reduced 2D collapse (plastic flow from the first steps): the update,
//    its state and the plasticity switch reach the user's code unchanged;
//  - a model's own state variable follows its point through the whole run: the void ratio e of a
//    model that updates 1 + e by det(I + L dt) each step equals (1 + e0) det F - 1 at every point
//    after the full collapse (0.15 s, the points handed to the ParticleHandler and back at
//    every re-sort into cells; on 4 ranks (ctest's run) with Load balance threshold 1.02, the
//    re-sorts move points between ranks and at least one repartition moves them with their cells,
//    asserted from the history), to round-off; the particle table holds it under its name;
//  - refused with a message naming the entry: Backend = cuda with a user model, a random
//    field on a user model, a state variable name with a space; a name registered twice is
//    refused too.
#include "../core/check.h"

#include <mpm/core/material/drucker_prager.h>
#include <mpm/dealii/material_library.h>
#include <mpm/dealii/parameters.h>
#include <mpm/dealii/simulator.h>
#include <mpm/dealii/strength_parameters.h>

#include <deal.II/base/mpi.h>

#include <algorithm>
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
  // The same with a state variable: the void ratio e, 1 + e = (1 + e0) V / V0, updated each step
  // by the volume ratio det(I + L dt) of the step (L dt = d_eps + d_spin), as F is.
  class DruckerPragerWithVoidRatio : public WrappedDruckerPrager
  {
  public:
    static void declare_parameters(dealii::ParameterHandler &prm)
    {
      WrappedDruckerPrager::declare_parameters(prm);
      prm.declare_entry("Initial void ratio", "0.6", dealii::Patterns::Double(0), "e0 (> 0).");
    }
    void parse_parameters(dealii::ParameterHandler &prm)
    {
      WrappedDruckerPrager::parse_parameters(prm);
      e0 = prm.get_double("Initial void ratio");
    }
    std::vector<StateVariable> state_variables() const override { return {{"void_ratio", e0}}; }
    void update_stress(const SymTensor<double> &d_eps, const Mat3<double> &d_spin, const bool plastic,
                       SymTensor<double> &stress, double &plastic_strain, double *state) const override
    {
      WrappedDruckerPrager::update_stress(d_eps, d_spin, plastic, stress, plastic_strain, nullptr);
      Mat3<double> step = Mat3<double>::identity();
      const int    voigt[3][3] = {{0, 3, 5}, {3, 1, 4}, {5, 4, 2}};
      for (int a = 0; a < 3; ++a)
        for (int b = 0; b < 3; ++b)
          step.a[a][b] += d_eps[voigt[a][b]] + d_spin.a[a][b];
      state[0] = (1 + state[0]) * determinant(step) - 1;
    }

  private:
    double e0 = 0;
  };

  // A model whose state variable name cannot name an output field.
  class BadStateName : public WrappedDruckerPrager
  {
  public:
    std::vector<StateVariable> state_variables() const override { return {{"void ratio", 0.5}}; }
  };
} // namespace

MPM_REGISTER_CONSTITUTIVE_MODEL(WrappedDruckerPrager, "wrapped drucker prager",
                                "The core's Drucker-Prager behind the user-model interface (a test).");
MPM_REGISTER_CONSTITUTIVE_MODEL(DruckerPragerWithVoidRatio, "drucker prager with void ratio",
                                "The test's Drucker-Prager with a void ratio state variable.");
MPM_REGISTER_CONSTITUTIVE_MODEL(BadStateName, "bad state name", "A state variable named with a space (a test).");

namespace
{
  std::string scene_text(const std::string &model, const std::string &extra = "", const int max_steps = 60)
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
    return text + "\nsubsection Solver\n set Maximum number of steps = " + std::to_string(max_steps) + "\nend\n"
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

  // The full collapse with the void ratio model: every point's e against its det F, in the run's
  // arrays and in the last particle table. Returns the largest |e - ((1 + e0) det F - 1)|.
  double void_ratio_follows_points(double &largest_volume_change)
  {
    const std::string directory = "output-user-model-state";
    const std::string text =
      scene_text("drucker prager with void ratio",
                 "subsection Material aluminium bars\n subsection drucker prager with void ratio\n"
                 "  set Initial void ratio = 0.65\n end\nend\n"
                 "subsection Output\n set Directory = " + directory + "\n set Output interval = 0.05\n"
                 " set Write particle table = true\nend\n"
                 "subsection Parallel\n set Load balance threshold = 1.02\nend\n",
                 100000);
    Simulator<2> simulator(parameters_from_string(text), MPI_COMM_WORLD);
    simulator.run();
    if (dealii::Utilities::MPI::n_mpi_processes(MPI_COMM_WORLD) > 1 &&
        dealii::Utilities::MPI::this_mpi_process(MPI_COMM_WORLD) == 0)
      {
        // Several ranks: the history's last row counts the repartitions (the grid is
        // partitioned by the points' work as it is built, so only the run's own count).
        std::ifstream            history(directory + "/history.csv");
        std::string              header, last, row;
        std::getline(history, header);
        while (std::getline(history, row))
          last = row;
        std::vector<std::string> names, values;
        std::stringstream        h(header), l(last);
        for (std::string item; std::getline(h, item, ',');)
          names.push_back(item);
        for (std::string item; std::getline(l, item, ',');)
          values.push_back(item);
        const auto at = std::find(names.begin(), names.end(), "n_repartitions");
        const double repartitions =
          at == names.end() || values.size() != names.size() ? -1 : std::stod(values[at - names.begin()]);
        std::printf("repartitions in the collapse on %u ranks: %g\n",
                    dealii::Utilities::MPI::n_mpi_processes(MPI_COMM_WORLD), repartitions);
        check(repartitions >= 1, "the grid is repartitioned (points move with their cells)", repartitions, 1);
      }
    const HostPoints<2, double> p = simulator.points();
    double worst = p.n_state_variables() == 1 && p.size() > 0 ? 0 : 1e300;
    largest_volume_change = 0;
    for (int i = 0; worst < 1e300 && i < p.size(); ++i)
      {
        const double J = p.deformation_gradient[0][i] * p.deformation_gradient[3][i] -
                         p.deformation_gradient[1][i] * p.deformation_gradient[2][i];
        worst = std::max(worst, std::abs(p.state_variables[0][i] - (1.65 * J - 1)));
        largest_volume_change = std::max(largest_volume_change, std::abs(J - 1));
      }

    // The last particle table of this rank: the void_ratio column against the F columns.
    const unsigned int rank = dealii::Utilities::MPI::this_mpi_process(MPI_COMM_WORLD);
    std::ifstream      table(directory + "/particle_table_00003." + std::to_string(rank) + ".csv");
    std::string        line;
    std::getline(table, line);
    std::vector<std::string> columns;
    std::stringstream        header(line);
    for (std::string name; std::getline(header, name, ',');)
      columns.push_back(name);
    auto column = [&](const std::string &name) {
      const auto at = std::find(columns.begin(), columns.end(), name);
      return at == columns.end() ? -1 : static_cast<int>(at - columns.begin());
    };
    const int e = column("void_ratio"), xx = column("F_xx"), xy = column("F_xy"), yx = column("F_yx"),
              yy = column("F_yy");
    int rows = 0;
    if (e < 0 || xx < 0 || xy < 0 || yx < 0 || yy < 0)
      worst = 1e300;
    while (worst < 1e300 && std::getline(table, line))
      {
        std::vector<double> v;
        std::stringstream   row(line);
        for (std::string value; std::getline(row, value, ',');)
          v.push_back(std::stod(value));
        worst = std::max(worst, std::abs(v[e] - (1.65 * (v[xx] * v[yy] - v[xy] * v[yx]) - 1)));
        ++rows;
      }
    if (rows != p.size())
      worst = 1e300;
    // Over every rank's points (each rank checks its own).
    largest_volume_change = dealii::Utilities::MPI::max(largest_volume_change, MPI_COMM_WORLD);
    return dealii::Utilities::MPI::max(worst, MPI_COMM_WORLD);
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

      double       volume_change = 0;
      const double void_ratio    = void_ratio_follows_points(volume_change);
      std::printf("void ratio after the collapse (0.15 s): largest |e - ((1 + e0) det F - 1)| %.3e over the points "
                  "and the particle table; largest |det F - 1| %.3e\n",
                  void_ratio, volume_change);
      check(volume_change > 1e-3, "the points change volume in the collapse", volume_change, 1e-3);
      check(void_ratio < 1e-12, "the void ratio state variable follows its point through the run and the output",
            void_ratio, 1e-12);
      check(throws_naming([]() { parameters_from_string(scene_text("bad state name")); }, "Material aluminium bars/Model"),
            "a state variable name with a space is refused, naming the entry");

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
