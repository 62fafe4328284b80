// A whole scene as one parameter file describes it: the MPM's parameters (dealii/parameters.h)
// and the pre-failure FEM stage's settings (fem/prefailure_parameters.h), each declared and
// parsed by its own layer from the same file. This layer sits above both; the executable and
// programs that run an FEM stage before the MPM read their scenes here.
#pragma once

#include <mpm/dealii/parameters.h>
#include <mpm/fem/prefailure_parameters.h>
#include <mpm/fem/prefailure_scene.h>

#include <ostream>
#include <string>

namespace mpm
{
  struct Scene
  {
    Parameters                mpm;        // everything but subsection Pre-failure analysis
    fem::PrefailureParameters prefailure; // subsection Pre-failure analysis (Method = none: no FEM stage)
  };

  // Reads a parameter file (read_parameters' two passes, with the FEM stage's subsection);
  // throws naming the entry on bad input.
  Scene read_scene(const std::string &filename);
  // The same from the text of a parameter file.
  Scene scene_from_string(const std::string &text);
  // Every entry of a scene of dimension dim with its default and documentation (--print-parameters).
  void print_scene_parameters(std::ostream &out, unsigned int dim, const std::string &style);

  // What the FEM stage is given of the scene: its settings, the materials, gravity, the output
  // folder and the prm's bodies it can mesh.
  fem::PrefailureScene prefailure_scene(const Scene &scene);
} // namespace mpm
