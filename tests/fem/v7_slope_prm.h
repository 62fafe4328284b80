// The Drucker-Prager slope of V7's geometry (H = 10 m, 2:1, gamma = 20 kN/m^3, c = 10 kPa,
// phi = 20 deg, psi = 0) as a parameter file for the FEM tests, with the given lines of the
// Pre-failure analysis subsection and output directory. Its FEM cells are 2 m.
#pragma once

#include <string>

inline std::string v7_drucker_prager_slope(const std::string &prefailure_lines, const std::string &directory)
{
  return R"(
set Dimension = 2
subsection Grid
  set Lower corner = 0, 0
  set Upper corner = 60, 14
  set Cell size = 1
end
subsection Solver
  set Gravity = 0, -9.81
end
subsection Material soil
  set Model = drucker prager
  subsection drucker prager
    set Young's modulus = 1e8
    set Poisson's ratio = 0.3
    set Cohesion        = 10e3
    set Friction angle  = 20
    set Dilatancy angle = 0
  end
end
subsection Material points
  subsection Body 1
    set Shape            = polygon
    set Polygon vertices = 0, 0; 40, 0; 20, 10; 0, 10
    set Upper corner     = 40, 10
    set Density          = 2038.7359836901
  end
end
subsection Pre-failure analysis
  set Cell size = 2
  set Load steps = 2
  set Continue with MPM = false
)" + prefailure_lines +
         "\nend\nsubsection Output\n  set Directory = " + directory + "\nend\n";
}
