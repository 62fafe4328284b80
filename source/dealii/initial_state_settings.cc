#include <mpm/dealii/initial_state_settings.h>
#include <mpm/dealii/parameter_error.h>

#include <deal.II/base/exceptions.h>
#include <deal.II/base/utilities.h>

#include <algorithm>
#include <cstdlib>

namespace mpm
{
  using dealii::ParameterHandler;
  namespace Patterns = dealii::Patterns;

  void InitialStateSettings::declare(ParameterHandler &prm)
  {
    prm.declare_entry("Source", "prm bodies", Patterns::Selection("prm bodies|FEM file"),
                      "prm bodies: the points of Material points/Body i (with their Initial stress: none or "
                      "geostatic). FEM file: the state an FEM program saved with mpm::save_fem_state (displacement, "
                      "quadrature-point stresses and plastic strain), handed over as Placement says; the bodies "
                      "of Material points are then not used.");
    prm.declare_entry("FEM file", "", Patterns::Anything(),
                      "Source = FEM file: the file written by mpm::save_fem_state (a path, relative to the "
                      "working directory).");
    prm.declare_entry("Placement", "quadrature points", Patterns::Selection("quadrature points|lattice"),
                      "quadrature points: one material point per quadrature point of the FEM, volume its JxW "
                      "(placement (a)). lattice: Points per cell direction^dim points per MPM cell inside the "
                      "deformed body, stresses projected from the quadrature points (placement (b)).");
    prm.declare_entry("Points per cell direction", "2", Patterns::Integer(1, 20),
                      "Placement = lattice: points per MPM cell along each direction.");
    prm.declare_entry("Projection degree", "-1", Patterns::Integer(-1, 10),
                      "Placement = lattice: polynomial degree of the cell-wise L2 projection of the quadrature-point "
                      "state (FE_DGQ); -1 = the FEM's displacement degree. Needs degree + 1 quadrature points per "
                      "direction.");
    prm.declare_entry("Materials", "", Patterns::Anything(),
                      "Source = FEM file, or Pre-failure analysis/Mesh = mesh file: 'id: name, density; ...' for every "
                      "material_id of the FEM mesh: the MPM "
                      "material (one of Materials/Names) and the density in kg/m^3 (> 0), e.g. '0: soil, 2000; 1: "
                      "rock, 2400'.");
    prm.declare_entry("Equilibrate", "false", Patterns::Bool(),
                      "true: before t = 0 (time stands still), damped steps with gravity in full and the points "
                      "held in place, only their stresses following the grid, until the grid is at rest: the "
                      "stresses then balance gravity in the MPM's own discretisation, and an undamped run starts "
                      "in equilibrium. A state in equilibrium in an FEM is not exactly in equilibrium on the MPM "
                      "grid (other shape functions, point quadrature), nor is a geostatic stress under a slope. "
                      "The run reports how much the stresses changed.");
    prm.declare_entry("Equilibration damping", "0.8", Patterns::Double(0, 1),
                      "Equilibrate: the local damping coefficient of the damped steps (Solver/Local damping's "
                      "form), 0 < D < 1.");
    prm.declare_entry("Equilibration tolerance", "1e-6", Patterns::Double(0),
                      "Equilibrate: at rest once the largest point speed has stayed below this multiple of "
                      "sqrt(|g| H) for one elastic wave transit of H (H: the bodies' extent along gravity; "
                      "without gravity the elastic wave speed replaces sqrt(|g| H)).");
    prm.declare_entry("Equilibration maximum steps", "100000", Patterns::Integer(1),
                      "Equilibrate: a state that is not at rest after this many damped steps stops the run "
                      "(a body that fails under its own weight never comes to rest).");
  }

  void InitialStateSettings::parse(ParameterHandler &prm, const std::vector<std::string> &material_names,
                                   const std::vector<MaterialParameters<double>> &material_parameters)
  {
    source                      = prm.get("Source");
    fem_file                    = prm.get("FEM file");
    placement                   = prm.get("Placement");
    points_per_direction        = prm.get_integer("Points per cell direction");
    projection_degree           = prm.get_integer("Projection degree");
    equilibrate                 = prm.get_bool("Equilibrate");
    equilibration_damping       = prm.get_double("Equilibration damping");
    equilibration_tolerance     = prm.get_double("Equilibration tolerance");
    equilibration_maximum_steps = prm.get_integer("Equilibration maximum steps");
    if (equilibrate && !(equilibration_damping > 0 && equilibration_damping < 1))
      parameter_error("Initial state/Equilibration damping", "must lie between 0 and 1 (exclusive) where Equilibrate = true.");
    if (equilibrate && !(equilibration_tolerance > 0))
      parameter_error("Initial state/Equilibration tolerance", "must be > 0 where Equilibrate = true.");
    if (source == "FEM file" && fem_file.empty())
      parameter_error("Initial state/FEM file", "Source = FEM file needs the file's name.");
    // Read where given: the FEM file needs them, and so does a pre-failure analysis of a mesh
    // file (run/scene.h checks that).
    if (source == "FEM file" || !dealii::Utilities::trim(prm.get("Materials")).empty())
      {
        for (const std::string &item : dealii::Utilities::split_string_list(prm.get("Materials"), ';'))
          {
            const std::string where = "Initial state/Materials";
            const auto        colon = item.find(':');
            const std::vector<std::string> rest =
              colon == std::string::npos ? std::vector<std::string>() :
                                           dealii::Utilities::split_string_list(item.substr(colon + 1), ',');
            if (rest.size() != 2)
              parameter_error(where, "'" + item + "' is not of the form 'id: material name, density'.");
            int    id      = -1;
            double density = 0;
            try
              {
                id      = dealii::Utilities::string_to_int(dealii::Utilities::trim(item.substr(0, colon)));
                density = dealii::Utilities::string_to_double(rest[1]);
              }
            catch (...)
              {
                parameter_error(where, "'" + item + "' is not of the form 'id: material name, density'.");
              }
            const auto name = std::find(material_names.begin(), material_names.end(), rest[0]);
            if (id < 0 || id > 255 || !(density > 0) || name == material_names.end() || materials.count(id))
              parameter_error(where, "'" + item + "': the id must be a material_id 0..255 given once, the name one of "
                          "Materials/Names, the density > 0.");
            if (material_parameters[name - material_names.begin()].field_parameter != FieldParameter::none)
              parameter_error(where, "material '" + rest[0] + "' has a random field, which the FEM hand-over does not carry.");
            materials[id] = {static_cast<unsigned int>(name - material_names.begin()), density};
          }
        if (materials.empty() && source == "FEM file")
          parameter_error("Initial state/Materials", "Source = FEM file needs at least one 'id: material name, density'.");
      }
  }
} // namespace mpm
