// custom_material: a constitutive model of the user's own, used from a parameter file.
//
// The story. A geotechnical engineer works with undrained clay and wants the model they trust
// for it (von Mises with the undrained strength s_u, in von_mises.cc) rather than one of the
// built-in ones. They write it in a file of their own program, give it a name, and from then
// on select it in a parameter file as any built-in model: "set Model = von mises". The
// dealii-mpm executable does not know the name; this program, which links the library and the
// model, does.
//
// To trust the model in a run-out, they check it where the answer is known: a vertical cut in
// clay stands when its stability number N = gamma H / s_u is below Taylor's 3.83 and collapses
// above it. The program
//   1. reads the scene, vertical_cut.prm (N = 2.5), or the file given on the command line;
//   2. runs it: after the elastic settling the face must stay put (it moves by millimetres);
//   3. runs it again with s_u lowered to N = 6 (one entry added to the same text): the cut must
//      collapse and run out by metres;
//   4. exits non-zero if either does not happen.
#include <mpm/dealii/parameters.h>
#include <mpm/dealii/simulator.h>

#include <deal.II/base/mpi.h>

#include <algorithm>
#include <fstream>
#include <iostream>
#include <sstream>

namespace
{
  // How far the face of the cut has moved during the plastic part of the run: the largest
  // horizontal position of any point, at the end, minus its value when plasticity starts.
  double face_advance(const std::string &scene, MPI_Comm communicator)
  {
    const mpm::Parameters parameters = mpm::parameters_from_string(scene);
    mpm::Simulator<2>     simulator(parameters, communicator);
    simulator.setup();

    const auto face = [&]() {
      const mpm::HostPoints<2, double> points = simulator.points();
      double                           x_max  = -1e300;
      for (std::size_t i = 0; i < points.size(); ++i)
        if (points.material[i] >= 0)
          x_max = std::max(x_max, points.position[0][i]);
      return dealii::Utilities::MPI::max(x_max, communicator);
    };

    while (simulator.time() < parameters.plasticity_start_time)
      simulator.advance();
    const double face_at_start = face();
    while (!simulator.finished())
      simulator.advance();
    simulator.finish();
    return face() - face_at_start;
  }
} // namespace

int main(int argc, char **argv)
{
  dealii::Utilities::MPI::MPI_InitFinalize mpi(argc, argv, 1);
  try
    {
      // 1. The scene text, as the executable would read it.
      const std::string file = argc > 1 ? argv[1] : CUSTOM_MATERIAL_SCENE;
      std::ifstream     in(file);
      AssertThrow(in, dealii::ExcMessage("cannot read the scene file '" + file + "'"));
      std::stringstream text;
      text << in.rdbuf();
      const std::string scene = text.str();

      // 2. N = 2.5: the cut stands.
      const double stands = face_advance(scene, MPI_COMM_WORLD);

      // 3. N = 6: s_u = gamma H / 6. A later "set" of the same entry wins.
      const double      gamma_H  = 2000 * 9.81 * 5;
      const std::string weakened = scene + "\nsubsection Material clay\n  subsection von mises\n"
                                           "    set Undrained shear strength = " +
                                   std::to_string(gamma_H / 6) + "\n  end\nend\n";
      const double collapses = face_advance(weakened, MPI_COMM_WORLD);

      // 4. The verdict. The bounds are wide on purpose: they separate standing from collapsing,
      // not one mesh from another.
      std::cout << "\nvertical cut, H = 5 m, after plasticity starts:\n"
                << "  the scene as given (vertical_cut.prm: N = 2.5): the face moves " << stands
                << " m (must be below 0.05 m: it stands)\n"
                << "  s_u lowered to N = 6: the face moves " << collapses << " m (must exceed 1 m: it collapses)\n";
      const bool ok = stands < 0.05 && collapses > 1.0;
      std::cout << (ok ? "PASSED" : "FAILED") << std::endl;
      return ok ? 0 : 1;
    }
  catch (const std::exception &e)
    {
      std::cerr << "custom_material: " << e.what() << std::endl;
      return 1;
    }
}
