#include <mpm/run/scene.h>
#include <mpm/dealii/parameter_error.h>

#include <deal.II/base/exceptions.h>

#include <cstdlib>

namespace mpm
{
  namespace
  {

    // The FEM stage's subsection, read into `settings`, and what it asks of the MPM's entries.
    ParameterSection prefailure_section(fem::PrefailureParameters &settings)
    {
      ParameterSection section;
      section.declare = [](dealii::ParameterHandler &prm, const unsigned int dim) {
        fem::PrefailureParameters::declare(prm, dim);
      };
      section.parse = [&settings](dealii::ParameterHandler &prm, const Parameters &mpm) {
        settings.parse(prm, mpm.dim);
        if (settings.analysis == fem::Analysis::none)
          return;
        if (mpm.initial_state.source == "FEM file")
          parameter_error("Initial state/Source", "the FEM file and a Pre-failure analysis are two initial states; choose one "
                                       "(Source = prm bodies, or Pre-failure analysis/Method = none).");
        if (settings.mesh == "mesh file" && mpm.initial_state.materials.empty())
          parameter_error("Initial state/Materials",
               "Pre-failure analysis/Mesh = mesh file needs at least one 'id: material name, density'.");
      };
      return section;
    }
  } // namespace

  Scene read_scene(const std::string &filename)
  {
    Scene scene;
    scene.mpm = read_parameters(filename, {prefailure_section(scene.prefailure)});
    return scene;
  }

  Scene scene_from_string(const std::string &text)
  {
    Scene scene;
    scene.mpm = parameters_from_string(text, {prefailure_section(scene.prefailure)});
    return scene;
  }

  void print_scene_parameters(std::ostream &out, const unsigned int dim, const std::string &style)
  {
    fem::PrefailureParameters unused;
    print_parameters(out, dim, style, {prefailure_section(unused)});
  }

  fem::PrefailureScene prefailure_scene(const Scene &scene)
  {
    const Parameters    &p = scene.mpm;
    fem::PrefailureScene s;
    s.settings          = scene.prefailure;
    s.material_names    = p.material_names;
    s.materials         = p.materials;
    s.mesh_materials    = p.initial_state.materials;
    s.gravity           = p.gravity;
    s.default_cell_size = p.cell_size;
    s.output_directory  = p.output.directory;
    for (std::size_t b = 0; b < p.bodies.size(); ++b)
      {
        fem::MeshedBody body;
        body.shape    = p.bodies[b].shape;
        body.lower    = p.bodies[b].lower;
        body.upper    = p.bodies[b].upper;
        body.polygon  = p.bodies[b].polygon;
        body.material = p.body_material[b];
        body.density  = p.bodies[b].density;
        s.bodies.push_back(body);
      }
    return s;
  }
} // namespace mpm
