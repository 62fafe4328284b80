#include <mpm/fem/prefailure_parameters.h>

#include <deal.II/base/exceptions.h>
#include <deal.II/base/utilities.h>

#include <cmath>

namespace mpm::fem
{
  using dealii::ExcMessage;
  using dealii::ParameterHandler;
  namespace Patterns = dealii::Patterns;

  namespace
  {
    const std::string section = "Pre-failure analysis/";

    [[noreturn]] void fail(const std::string &entry, const std::string &what)
    {
      AssertThrow(false, ExcMessage("Parameter '" + section + entry + "': " + what));
      throw; // not reached
    }

    Analysis analysis_from(const std::string &name)
    {
      if (name == "gravity loading")
        return Analysis::gravity_loading;
      if (name == "K0 procedure")
        return Analysis::k0_procedure;
      if (name == "strength reduction")
        return Analysis::strength_reduction;
      return Analysis::none;
    }

    double number(const std::string &entry, const std::string &text, const std::string &allowed = "a number")
    {
      try
        {
          return dealii::Utilities::string_to_double(dealii::Utilities::trim(text));
        }
      catch (...)
        {
          fail(entry, "'" + text + "' is not " + allowed + ".");
        }
    }
  } // namespace

  std::string to_string(const Analysis analysis)
  {
    switch (analysis)
      {
        case Analysis::gravity_loading:
          return "gravity loading";
        case Analysis::k0_procedure:
          return "K0 procedure";
        case Analysis::strength_reduction:
          return "strength reduction";
        default:
          return "none";
      }
  }

  void PrefailureParameters::declare(ParameterHandler &prm, const unsigned int dim)
  {
    prm.enter_subsection("Pre-failure analysis");
    prm.declare_entry(
      "Method", "none", Patterns::Selection("none|gravity loading|K0 procedure|strength reduction"),
      "An implicit, quasi-static, small-strain elasto-plastic FEM analysis of the body before the MPM "
      "(doc/prefailure.md). none: no FEM stage. gravity loading: the body's weight applied in Load steps, "
      "Newton with the consistent tangent of the materials' return mappings. K0 procedure: vertical stress "
      "from the overburden of horizontal layers, horizontal stress K0 times it, then one equilibrium step "
      "(exact for horizontal ground). strength reduction: the stresses of 'Initial stresses', then c, "
      "tan(phi) and tan(psi) divided by a factor F raised until no equilibrium is found (Newton and the "
      "initial-stiffness iterations both fail): the factor of safety.");
    prm.declare_entry("Initial stresses", "gravity loading", Patterns::Selection("gravity loading|K0 procedure"),
                      "Method = strength reduction: how the stresses before the reduction are made, at F = "
                      "Minimum factor.");
    prm.declare_entry("Mesh", "prm bodies", Patterns::Selection("prm bodies|mesh file"),
                      "prm bodies: the one body of Material points (Shape box or polygon) meshed with "
                      "quadrilaterals of about Cell size (in 3D the polygon extruded along y, as the MPM's body "
                      "is); boundary ids 0/1 on the faces at x min/max of its bounding box, 2/3 at the next axis' "
                      "min/max, 4/5 at z min/max in 3D, 6 elsewhere (a slope's face). mesh file: the mesh of "
                      "'Mesh file', its cells' material ids named by Initial state/Materials.");
    prm.declare_entry("Mesh file", "", Patterns::Anything(),
                      "Mesh = mesh file: a Gmsh .msh or UCD .inp/.ucd file (deal.II GridIn) of quadrilaterals "
                      "(hexahedra in 3D), material ids from its physical groups, boundary ids from its boundary "
                      "physical groups.");
    prm.declare_entry("Cell size", "0", Patterns::Double(0),
                      "Mesh = prm bodies: the largest edge of the coarse mesh's cells (m); 0 = Grid/Cell size.");
    prm.declare_entry("Global refinements", "0", Patterns::Integer(0, 8),
                      "Times the coarse mesh (either source) is refined uniformly.");
    prm.declare_entry("Polynomial degree", "2", Patterns::Integer(1, 2),
                      "Degree of the displacement's FE_Q elements: 2 (the default; linear elements lock and "
                      "over-predict the factor of safety) or 1.");
    prm.declare_entry("Boundary conditions",
                      dim == 2 ? "0: roller; 1: roller; 2: fixed" : "0: roller; 1: roller; 2: roller; 3: roller; 4: fixed",
                      Patterns::Map(Patterns::Integer(0, 254), Patterns::Selection("fixed|roller|periodic|free"), 0,
                                    Patterns::Map::max_int_value, ";", ":"),
                      "'id: condition; ...' with condition fixed (every displacement component zero), roller "
                      "(the component normal to the boundary zero; the boundary must be a plane normal to an "
                      "axis), periodic (ids 2d and 2d+1, the opposite faces of the body's bounding box normal to "
                      "axis d, both named periodic: the displacement is the same on both, e.g. a long slope "
                      "modelled by one slice) or free. Ids not named are free. The default fixes the base and "
                      "holds the sides by rollers.");
    prm.declare_entry("Load steps", "4", Patterns::Integer(1, 10000),
                      "Gravity loading: gravity is applied in this many equal increments.");
    prm.declare_entry("Maximum Newton iterations", "200", Patterns::Integer(1, 10000),
                      "Newton iterations of one load step or one factor before Newton counts as not converged; "
                      "then the initial-stiffness iterations try (Maximum initial stiffness iterations), and if "
                      "they fail too, the load step is halved or, under strength reduction, the factor fails.");
    prm.declare_entry("Maximum initial stiffness iterations", "1000", Patterns::Integer(0, 1000000),
                      "Where Newton does not converge, the load step or factor is tried again from Newton's "
                      "iterate of least residual with the initial-stiffness method (the elastic stiffness, factorised "
                      "once; Griffiths & Lane's iteration), up to this many iterations; it is slower but does "
                      "not cycle where non-associated plasticity makes Newton cycle. 0: Newton only.");
    prm.declare_entry("Initial stiffness tolerance", "1e-5", Patterns::Double(0),
                      "The initial-stiffness iterations have converged when the residual's norm is below this "
                      "multiple of the full gravity load's norm. Their rate is linear, and slow near failure, so "
                      "this is looser than Residual tolerance; under strength reduction the factor of safety "
                      "found this way depends on it and on Maximum initial stiffness iterations "
                      "(doc/prefailure.md).");
    prm.declare_entry("Residual tolerance", "1e-8", Patterns::Double(0),
                      "Newton has converged when the residual's norm is below this multiple of the norm of the "
                      "full gravity load vector (the body's weight on the nodes).");
    prm.declare_entry("Line search", "true", Patterns::Bool(),
                      "true: each Newton update is halved (up to 6 times) until it lowers the residual.");
    prm.declare_entry("Linear solver", "direct", Patterns::Selection("direct|iterative"),
                      "direct: Trilinos' Amesos KLU (robust, for up to a few 10^5 unknowns). iterative: GMRES "
                      "preconditioned by Trilinos' algebraic multigrid (the tangent of non-associated plasticity "
                      "is not symmetric).");
    prm.declare_entry("K0", "-1", Patterns::Double(),
                      "K0 procedure: sigma_h = K0 sigma_v in every material; a negative value takes nu/(1 - nu) "
                      "of each material (the elastic, laterally confined layer).");
    prm.declare_entry("Minimum factor", "1", Patterns::Double(0),
                      "Strength reduction: the factor F of the initial stresses (> 0), where the search starts.");
    prm.declare_entry("Maximum factor", "10", Patterns::Double(0),
                      "Strength reduction: the search stops here if no factor has failed by then (reported as a "
                      "factor of safety above it).");
    prm.declare_entry("Factor increment", "0.1", Patterns::Double(0),
                      "Strength reduction: F is raised by this much from each converged factor; where a factor "
                      "fails, the step is halved and the failed factor is tried again from nearer.");
    prm.declare_entry("Factor tolerance", "0.005", Patterns::Double(0),
                      "Strength reduction: the search stops when the step has been halved below this; the last "
                      "converged factor (the factor of safety) and the lowest failing one then differ by less "
                      "than twice this.");
    prm.declare_entry("Monitor point", "", Patterns::Anything(),
                      "Strength reduction: the F-displacement curve reads the displacement (since the start of "
                      "the reduction) of the mesh vertex nearest this point, e.g. the crest; empty = the largest "
                      "nodal displacement.");
    prm.declare_entry("Continue with MPM", "true", Patterns::Bool(),
                      "true: after the analysis the MPM runs to Solver/End time from its state (one material "
                      "point per quadrature point: stress, plastic strain, the deformed position), on the MPM's "
                      "Grid. false: the run ends with the analysis.");
    prm.declare_entry("MPM strength factor", "1", Patterns::Anything(),
                      "The MPM continues with c, tan(phi) and tan(psi) of every material divided by this factor "
                      "(> 0): 1 = the prm's strengths (with their softening), or 'failing factor' (strength "
                      "reduction only): the lowest factor at which the FEM found no equilibrium, so that the "
                      "slope handed over at the last converged factor runs out.");
    prm.leave_subsection();
  }

  void PrefailureParameters::parse(ParameterHandler &prm, const unsigned int dim)
  {
    prm.enter_subsection("Pre-failure analysis");
    analysis           = analysis_from(prm.get("Method"));
    initial_stresses   = analysis_from(prm.get("Initial stresses"));
    mesh               = prm.get("Mesh");
    mesh_file          = prm.get("Mesh file");
    cell_size          = prm.get_double("Cell size");
    global_refinements = prm.get_integer("Global refinements");
    degree             = prm.get_integer("Polynomial degree");
    load_steps         = prm.get_integer("Load steps");
    maximum_newton_iterations = prm.get_integer("Maximum Newton iterations");
    maximum_initial_stiffness_iterations = prm.get_integer("Maximum initial stiffness iterations");
    initial_stiffness_tolerance          = prm.get_double("Initial stiffness tolerance");
    residual_tolerance = prm.get_double("Residual tolerance");
    line_search        = prm.get_bool("Line search");
    linear_solver      = prm.get("Linear solver");
    k0                 = prm.get_double("K0");
    minimum_factor     = prm.get_double("Minimum factor");
    maximum_factor     = prm.get_double("Maximum factor");
    factor_increment   = prm.get_double("Factor increment");
    factor_tolerance   = prm.get_double("Factor tolerance");

    boundary_conditions.clear();
    for (const std::string &item : dealii::Utilities::split_string_list(prm.get("Boundary conditions"), ';'))
      {
        const auto colon = item.find(':');
        if (colon == std::string::npos)
          fail("Boundary conditions", "'" + item + "' is not of the form 'id: fixed|roller|periodic|free'.");
        const double      id   = number("Boundary conditions", item.substr(0, colon));
        const std::string kind = dealii::Utilities::trim(item.substr(colon + 1));
        if (!(id >= 0 && id <= 254 && id == std::floor(id)) || boundary_conditions.count(static_cast<unsigned>(id)))
          fail("Boundary conditions", "'" + item + "': the id must be a boundary id 0..254, named once.");
        if (kind != "fixed" && kind != "roller" && kind != "periodic" && kind != "free")
          fail("Boundary conditions", "'" + item + "': the condition must be one of fixed, roller, periodic, free.");
        boundary_conditions[static_cast<unsigned int>(id)] =
          kind == "fixed"    ? BoundaryCondition::fixed :
          kind == "roller"   ? BoundaryCondition::roller :
          kind == "periodic" ? BoundaryCondition::periodic :
                               BoundaryCondition::free;
      }
    for (const auto &[id, kind] : boundary_conditions)
      if (kind == BoundaryCondition::periodic)
        {
          const unsigned int partner = id ^ 1u;
          if (id >= 2 * dim || !boundary_conditions.count(partner) ||
              boundary_conditions.at(partner) != BoundaryCondition::periodic)
            fail("Boundary conditions", "boundary id " + std::to_string(id) +
                                          " is periodic; periodic ids come in the pairs of the bounding box's faces "
                                          "(0 and 1: x; 2 and 3: the second axis" +
                                          (dim == 3 ? std::string("; 4 and 5: z") : std::string()) +
                                          "), both named periodic.");
        }

    monitor_point.clear();
    const std::string monitor = dealii::Utilities::trim(prm.get("Monitor point"));
    if (!monitor.empty())
      {
        for (const std::string &x : dealii::Utilities::split_string_list(monitor, ','))
          monitor_point.push_back(number("Monitor point", x));
        if (monitor_point.size() != dim)
          fail("Monitor point", "needs " + std::to_string(dim) + " coordinates, got '" + monitor + "'.");
      }
    continue_with_mpm                 = prm.get_bool("Continue with MPM");
    const std::string strength_factor = dealii::Utilities::trim(prm.get("MPM strength factor"));
    mpm_strength_from_failure         = strength_factor == "failing factor";
    if (!mpm_strength_from_failure)
      {
        mpm_strength_factor = number("MPM strength factor", strength_factor, "a number > 0 or 'failing factor'");
        if (!(mpm_strength_factor > 0))
          fail("MPM strength factor", "must be a number > 0 or 'failing factor', got '" + strength_factor + "'.");
      }
    prm.leave_subsection();

    if (analysis == Analysis::none)
      return;
    if (mpm_strength_from_failure && analysis != Analysis::strength_reduction)
      fail("MPM strength factor", "'failing factor' needs Method = strength reduction.");
    if (mesh == "mesh file" && mesh_file.empty())
      fail("Mesh file", "Mesh = mesh file needs the file's name.");
    if (analysis == Analysis::strength_reduction)
      {
        if (!(minimum_factor > 0))
          fail("Minimum factor", "must be > 0, got " + std::to_string(minimum_factor) + ".");
        if (!(maximum_factor > minimum_factor))
          fail("Maximum factor", "the factor range [Minimum factor, Maximum factor] = [" +
                                   std::to_string(minimum_factor) + ", " + std::to_string(maximum_factor) +
                                   "] is empty; Maximum factor must exceed Minimum factor.");
        if (!(factor_increment > 0))
          fail("Factor increment", "must be > 0.");
        if (!(factor_tolerance > 0) || !(factor_tolerance < factor_increment))
          fail("Factor tolerance", "must be > 0 and below Factor increment (" + std::to_string(factor_increment) + ").");
        // A step below the round-off of F leaves F where it was: the search then tried the same
        // factor for ever (Factor increment = 1e-300: F = 1 + 1e-300 is F = 1).
        if (!(factor_tolerance >= 1e-9 * maximum_factor))
          fail("Factor tolerance", "must be at least 1e-9 x Maximum factor: the search cannot tell closer "
                                   "factors apart.");
      }
    if (!(residual_tolerance > 0))
      fail("Residual tolerance", "must be > 0.");
    if (maximum_initial_stiffness_iterations > 0 && !(initial_stiffness_tolerance >= residual_tolerance))
      fail("Initial stiffness tolerance", "must be at least Residual tolerance (" + std::to_string(residual_tolerance) +
                                            "): it is the looser test of the slower fallback.");
  }
} // namespace mpm::fem
