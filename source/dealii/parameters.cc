#include <mpm/dealii/guards.h>
#include <mpm/dealii/parameter_error.h>
#include <mpm/dealii/material_library.h>
#include <mpm/dealii/material_points.h>
#include <mpm/dealii/method_choice.h>
#include <mpm/dealii/parameters.h>
#include <mpm/dealii/prm_reading.h>

#include <deal.II/base/exceptions.h>
#include <deal.II/base/mpi.h>
#include <deal.II/base/utilities.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <fstream>
#include <limits>
#include <iomanip>
#include <set>
#include <sstream>

namespace mpm
{
  using dealii::ExcMessage;
  using dealii::ParameterHandler;
  namespace Patterns = dealii::Patterns;
  using namespace prm_reading;

  namespace
  {
    // Output/Particle fields: each a field of the run's points (PropertyLayout::fields, whose
    // names depend on the dimension and the models' state variables), or id or position.
    template <int dim>
    void check_particle_fields_of(const Parameters &p)
    {
      std::vector<std::string> allowed;
      for (const std::string &field : PropertyLayout<dim>(p.point_fields, p.state_variable_names()).fields())
        if (std::find(allowed.begin(), allowed.end(), field) == allowed.end())
          allowed.push_back(field);
      for (const std::string &given : p.output.particle_fields)
        if (given == "all")
          parameter_error("Output/Particle fields", "'all' stands alone; it cannot be combined with other fields.");
        else if (given != "id" && given != "position" &&
            std::find(allowed.begin(), allowed.end(), given) == allowed.end())
          parameter_error("Output/Particle fields", "'" + given + "' is not a field of the points. Allowed: all, or a list of " +
                                           join(allowed) + " (id and position are always written).");
    }

    void check_particle_fields(const Parameters &p)
    {
      if (p.dim == 2)
        check_particle_fields_of<2>(p);
      else
        check_particle_fields_of<3>(p);
    }

    // First pass: only what decides how the full set of entries is declared.
    void declare_layout(ParameterHandler &prm)
    {
      prm.declare_entry("Dimension", "2", Patterns::Integer(2, 3),
                        "Space dimension of the run: 2 (plane strain) or 3.");
      prm.enter_subsection("Materials");
      prm.declare_entry("Names", "soil", Patterns::List(Patterns::Anything(), 1),
                        "Comma-separated names of the materials; each has a subsection 'Material <name>'.");
      prm.leave_subsection();
      prm.enter_subsection("Material points");
      prm.declare_entry("Number of bodies", "1", Patterns::Integer(1, 1000),
                        "Number of bodies of material points; each has a subsection 'Body <i>', i = 1..n.");
      prm.leave_subsection();
    }

    bool test_shapes_registered = false;

    std::string shape_pattern()
    {
      std::string pattern;
      for (const std::string &name : shape_names(test_shapes_registered, [](auto) { return true; }))
        pattern += (pattern.empty() ? "" : "|") + name;
      return pattern;
    }

    // Each member's name and clause, then what the one-rank members need.
    std::string shape_documentation()
    {
      std::vector<std::string> clauses;
      for_each_shape([&](ShapeFunction, auto member) {
        using Member = decltype(member);
        if (Member::owner == ShapeOwner::always || test_shapes_registered)
          clauses.push_back(std::string(Member::name) + " (" + Member::description + ")");
      });
      return "Grid shape functions: " + join_or(clauses) +
             ". CPDI and CPDI2q: one MPI rank, Grid/Nodes = all. Cubic B-spline GIMP: one MPI rank; "
             "Grid/Nodes = near material needs Active block size >= 2.";
    }
  } // namespace

  void Parameters::declare(ParameterHandler &prm, const unsigned int dim, const unsigned int n_bodies,
                           const std::vector<std::string> &material_names)
  {
    declare_layout(prm);

    GridSettings::declare(prm, dim);

    prm.enter_subsection("Solver");
    prm.declare_entry("End time", "1", Patterns::Double(0), "Simulated end time (s).");
    prm.declare_entry("Update scheme", "MUSL", Patterns::Selection("MUSL|USL|USF"),
                      "Explicit update scheme: MUSL (modified update stress last, default), USL or USF.");
    prm.declare_entry("Shape function", "GIMP", Patterns::Selection(shape_pattern()), shape_documentation());
    prm.declare_entry("GIMP domain update", "none", Patterns::Selection("none|det F|F_ii|U"),
                      "How GIMP particle domains follow the deformation: none (uGIMP), det F (cpGIMP, "
                      "half-lengths scaled by det(F)^(1/dim)), F_ii (cpGIMP, half-length i scaled by F_ii; exact "
                      "for stretch along the axes, the domain vanishes under a rotation by 90 degrees) or U "
                      "(cpGIMP, half-length i scaled by U_ii, U the stretch tensor of the polar decomposition "
                      "F = R U: F_ii's accuracy under stretch, unchanged by rotation). Only with Shape function = "
                      "GIMP or cubic B-spline GIMP.");
    prm.declare_entry("Time step", "adaptive", Patterns::Selection("adaptive|fixed"),
                      "adaptive: dt = CFL number * h / (c_el + max |v_p|); fixed: dt = Fixed time step.");
    prm.declare_entry("CFL number", "0.5", Patterns::Double(0, 1),
                      "Courant number alpha of the adaptive time step, 0 < alpha <= 1.");
    prm.declare_entry("Fixed time step", "1e-4", Patterns::Double(0),
                      "Time step (s) when Time step = fixed; must not exceed h / c_el.");
    prm.declare_entry("Local damping", "0", Patterns::Double(0, 1),
                      "Local (Cundall) damping D, 0 <= D < 1: each component of the nodal force is reduced by "
                      "D times a magnitude against the nodal velocity, f_i <- f_i - D |.| sign(v_i) (see Local "
                      "damping form).");
    prm.declare_entry("Local damping form", "per component", Patterns::Selection("per component|force norm"),
                      "The magnitude in Local damping: per component, f_i <- f_i - D |f_i| sign(v_i) (Cundall; "
                      "a body in static equilibrium is not held by it); force norm, f_i <- f_i - D |f| sign(v_i) "
                      "with |f| the norm of the whole nodal force, fixed components included (ep2-3De's form: a "
                      "large force in one direction resists motion in the others like friction and can hold a "
                      "body away from equilibrium; doc/validation-v5.md).");
    prm.declare_entry("Local damping threshold", "0", Patterns::Double(0),
                      "Velocity components of a node at or below this speed (m/s) are not damped. ep2-3De uses "
                      "1e-3 m/s; with Local damping form = force norm a threshold is needed, since a component "
                      "at rest up to round-off is otherwise braked by D |f| in a direction that round-off picks.");
    prm.declare_entry("FLIP fraction", "1", Patterns::Double(0, 1),
                      "Velocity update: 1 = pure FLIP, 0 = pure PIC, in between a blend. Not used with "
                      "Velocity transfer = APIC or TPIC.");
    prm.declare_entry("FLIP at fixed nodes", "no change", Patterns::Selection("no change|velocity change"),
                      "What FLIP passes to the points from a node component that a boundary holds fixed (a "
                      "no-slip base, a roller's normal). no change (ep2-3De's): nothing, so a point beside a "
                      "no-slip base keeps the velocity it had while the base stops it (with pure FLIP a settled "
                      "heap keeps points at rest with FLIP velocities up to 0.8 m/s; doc/methods.md). velocity "
                      "change: the change the boundary made, from the node's velocity before the update to zero, as "
                      "at every other node: the heap at rest loses those velocities; with pure FLIP it moves the "
                      "noise between points instead (warned of: use it with FLIP fraction 0.99-0.995). Not used "
                      "with Velocity transfer = APIC or TPIC (PIC's velocity).");
    prm.declare_entry("Velocity transfer", "FLIP/PIC blend", Patterns::Selection("FLIP/PIC blend|APIC|TPIC"),
                      "FLIP/PIC blend: the points' velocities by FLIP fraction. APIC and TPIC: each point also "
                      "carries an affine velocity matrix C (output as the fields apic_C_xx, apic_C_xy, ...), its "
                      "momentum reaches the grid as m N (v + C (x_i - x_p)) and the grid gives back PIC's velocity "
                      "and C; both keep angular momentum through the transfers without FLIP's noise. TPIC "
                      "(Taylor PIC): C = sum_i v_i grad N_i, with any Shape function. APIC (Jiang et al. 2015): "
                      "C = B D^-1 with the B-splines' constant D (h^2/4 quadratic, h^2/3 cubic), equal to TPIC's "
                      "for linear; it needs Shape function = linear, quadratic B-spline or cubic B-spline. Both "
                      "backends. C starts at zero.");
    prm.declare_entry("Method", "as set", Patterns::Selection("as set|auto"),
                      "as set: Shape function, GIMP domain update, FLIP fraction, Velocity transfer and the "
                      "materials' Elastic law as given. auto: the program sets them to the cheapest method of its "
                      "method study (doc/methods.md) whose error, measured on the study's scene of the kind that "
                      "Method scene names at the same resolution (cells across the bodies' largest extent), is at "
                      "most Method tolerance; the log says what it picked and why. The scene's other settings "
                      "(damping, pressure averaging, update scheme) stay as given.");
    prm.declare_entry("Method scene", "run-out", Patterns::Selection("run-out|compression|bending|large stretch"),
                      "Method = auto: the study's scene whose errors stand for this one. run-out: the granular "
                      "collapse V3 (error: r.m.s. of the relative errors of toe, top-left height and slope against "
                      "the experiment); compression: the elastic column V1 (stress norm); bending: the cantilever "
                      "V2 (tip deflection); large stretch: the manufactured solution (L2 position error over the "
                      "amplitude).");
    prm.declare_entry("Method tolerance", "0.05", Patterns::Double(0),
                      "Method = auto: the largest expected error, in the error measure of Method scene's scene "
                      "(relative: 0.05 is 5%). If no method of the study is expected to reach it at the scene's "
                      "resolution, the run stops and says what the most accurate method would give.");
    prm.declare_entry("Gravity", zeros(dim, -9.81), point_pattern(dim),
                      "Gravitational acceleration vector (m/s^2).");
    prm.declare_entry("Gravity ramp time", "0", Patterns::Double(0),
                      "Gravity grows linearly from 0 to its full value over this time (s); 0 = applied at once.");
    prm.declare_entry("Plasticity start time", "0", Patterns::Double(0),
                      "Plastic models behave elastically before this time (s), so that the geostatic stress "
                      "settles under gravity before failure can start; 0 = plastic from the start.");
    prm.declare_entry("Pressure averaging", "false", Patterns::Bool(),
                      "true: after the constitutive update every point of a grid cell gets the volume-weighted "
                      "mean pressure of the points in that cell (deviatoric stress kept), against volumetric "
                      "locking, as in ep2-3De. false: no averaging. MPI runs: cells near partition boundaries are "
                      "summed over ranks.");
    prm.declare_entry("Maximum number of steps", "0", Patterns::Integer(0),
                      "Stop after this many steps even before End time; 0 = no limit.");
    prm.declare_entry("Maximum predicted steps", "1e9", Patterns::Double(0),
                      "A run whose first time step predicts more steps than this to End time (End time / dt, dt "
                      "from the CFL number, Grid/Cell size and the elastic wave speed of the bodies' Young's "
                      "modulus, Poisson's ratio and Density, or the Fixed time step; at most Maximum number of "
                      "steps) is refused before it starts: it would not end (a mistyped exponent?). 0 = no limit "
                      "(doc/guards.md).");
    prm.leave_subsection();

    MaterialSettings::declare(prm, dim, material_names);
    BodySettings::declare(prm, dim, n_bodies, material_names);

    prm.enter_subsection("Output");
    OutputSettings::declare(prm);
    prm.leave_subsection();

    prm.enter_subsection("Checkpoint");
    CheckpointSettings::declare(prm);
    prm.leave_subsection();

    prm.enter_subsection("Parallel");
    ParallelSettings::declare(prm);
    prm.leave_subsection();

    prm.enter_subsection("Initial state");
    InitialStateSettings::declare(prm);
    prm.leave_subsection();

    prm.enter_subsection("Backend");
    BackendSettings::declare(prm);
    prm.leave_subsection();

    prm.enter_subsection("Resources");
    prm.declare_entry("Memory limit", "0", Patterns::Double(0),
                      "Memory (GB, 1e9 bytes) the whole run may take, all ranks together. The run's memory is "
                      "estimated from the prm (grid cells, material points from the bodies' volumes and point "
                      "spacing, random fields) before anything is allocated, and the run is refused, naming the "
                      "entry that needs the most, where the estimate exceeds this limit. 0 = the memory available "
                      "on each node (MemAvailable of /proc/meminfo) shared by the ranks it holds (doc/guards.md).");
    prm.leave_subsection();
  }

  void register_test_shapes()
  {
    test_shapes_registered = true;
  }

  bool Parameters::tracks_corners() const
  {
    return shape_is(shape_function, [](auto member) { return decltype(member)::tracks_corners; });
  }

  void Parameters::parse(ParameterHandler &prm)
  {
    dim = prm.get_integer("Dimension");

    GridSettings::parse(prm, dim);

    prm.enter_subsection("Solver");
    end_time = prm.get_double("End time");
    const std::string s = prm.get("Update scheme");
    scheme = s == "USL" ? UpdateScheme::usl : (s == "USF" ? UpdateScheme::usf : UpdateScheme::musl);
    const std::string shape = prm.get("Shape function");
    shape_function = ShapeFunction::linear; // the pattern admits only the members' names
    for_each_shape([&](const ShapeFunction tag, auto member) {
      if (shape == decltype(member)::name)
        shape_function = tag;
    });
    // Not a tensor product (CPDI): a domain stretched by the flow reaches any distance.
    const bool cpdi_family = !shape_is(shape_function, [](auto member) { return decltype(member)::tensor_product; });
    if (dim == 3 && !shape_is(shape_function, [](auto member) { return decltype(member)::in_3d; }))
      parameter_error("Solver/Shape function", shape + " is two-dimensional; in 3D use " +
                                    join_or(shape_names(test_shapes_registered, [](auto member) {
                                      return decltype(member)::in_3d;
                                    })) + ".");
    const std::string du = prm.get("GIMP domain update");
    domain_update = du == "det F" ? DomainUpdate::det_F :
                    du == "F_ii"  ? DomainUpdate::stretch :
                    du == "U"     ? DomainUpdate::U : DomainUpdate::none;
    if (!shape_is(shape_function, [](auto member) { return decltype(member)::point_domain; }) &&
        domain_update != DomainUpdate::none)
      parameter_error("Solver/GIMP domain update", "'" + du + "' needs Shape function = " +
                                        join_or(shape_names(test_shapes_registered, [](auto member) {
                                          return decltype(member)::point_domain;
                                        })) + "; with "
                                        "Shape function = " + shape + " the only allowed value is none.");
    if (cpdi_family && active_block_cells > 0)
      parameter_error("Grid/Nodes", "'near material' keeps the nodes within a fixed number of cells of each point's cell, "
                         "but a CPDI domain stretched by the flow reaches farther; with Shape function = " + shape +
                         " the only allowed value is all.");
    if (shape_function == ShapeFunction::bspline3_gimp && active_block_cells == 1)
      parameter_error("Grid/Active block size", "the cubic B-spline GIMP's stencil reaches two cells out of a point's cell, "
                                     "beyond the nodes that blocks of 1 cell keep around it; with Shape function = " +
                                       shape + " and Nodes = near material the allowed values are 2 to 64 "
                                       "(2: the nodes are chosen again whenever a point leaves its cell).");
    adaptive_time_step = prm.get("Time step") == "adaptive";
    cfl                = prm.get_double("CFL number");
    if (!(cfl > 0))
      parameter_error("Solver/CFL number", "must satisfy 0 < CFL <= 1, got " + prm.get("CFL number") + ".");
    fixed_time_step = prm.get_double("Fixed time step");
    if (!adaptive_time_step && !(fixed_time_step > 0))
      parameter_error("Solver/Fixed time step", "must be > 0 when Time step = fixed.");
    damping = prm.get_double("Local damping");
    if (!(damping < 1))
      parameter_error("Solver/Local damping", "must satisfy 0 <= D < 1, got " + prm.get("Local damping") + ".");
    damping_form = prm.get("Local damping form") == "force norm" ? LocalDampingForm::force_norm
                                                                  : LocalDampingForm::per_component;
    damping_threshold = prm.get_double("Local damping threshold");
    flip_fraction     = prm.get_double("FLIP fraction");
    flip_fixed_velocity_change = prm.get("FLIP at fixed nodes") == "velocity change";
    const std::string transfer = prm.get("Velocity transfer");
    apic                       = transfer == "APIC" || transfer == "TPIC";
    affine_matrix = transfer == "APIC" ? AffineMatrix::b_d_inverse : AffineMatrix::velocity_gradient;
    if (transfer == "APIC" && !shape_is(shape_function, [](auto member) { return decltype(member)::apic; }))
      parameter_error("Solver/Velocity transfer", "APIC needs Shape function = " +
                                       join_or(shape_names(false, [](auto member) { return decltype(member)::apic; })) +
                                       " "
                                       "(its D_p is constant only for the B-splines; with GIMP or CPDI a D_p "
                                       "computed per point turns singular at the grid's faces); with Shape "
                                       "function = " + shape + " use Velocity transfer = TPIC.");
    if (apic)
      flip_fraction = 0; // APIC's velocity is PIC's plus the affine part
    const bool        method_auto      = prm.get("Method") == "auto";
    const std::string method_scene     = prm.get("Method scene");
    const double      method_tolerance = prm.get_double("Method tolerance");
    if (method_auto && !(method_tolerance > 0))
      parameter_error("Solver/Method tolerance", "must be > 0 with Method = auto, got " + prm.get("Method tolerance") + ".");
    gravity           = get_point(prm, "Gravity", "Solver/");
    gravity_ramp_time = prm.get_double("Gravity ramp time");
    max_steps         = prm.get_integer("Maximum number of steps");
    max_predicted_steps = prm.get_double("Maximum predicted steps");
    plasticity_start_time = prm.get_double("Plasticity start time");
    pressure_averaging    = prm.get_bool("Pressure averaging");
    prm.leave_subsection();

    MaterialSettings::parse(prm);

    prm.enter_subsection("Initial state");
    initial_state.parse(prm, material_names, materials);
    prm.leave_subsection();
    if (initial_state.equilibrate && gravity_ramp_time > 0)
      parameter_error("Initial state/Equilibrate", "the equilibration holds gravity in full; it needs Solver/Gravity ramp "
                                        "time = 0 (a ramp after it would take the load off the state).");

    prm.enter_subsection("Material points");
    const unsigned int n_bodies = initial_state.source == "FEM file" ? 0 : prm.get_integer("Number of bodies");
    prm.leave_subsection();
    BodySettings::parse(prm, dim, n_bodies, material_names, lower, upper);

    prm.enter_subsection("Output");
    output.parse(prm);
    prm.leave_subsection();

    prm.enter_subsection("Checkpoint");
    checkpoint.parse(prm, output.directory);
    prm.leave_subsection();

    prm.enter_subsection("Parallel");
    parallel.parse(prm);
    prm.leave_subsection();

    prm.enter_subsection("Backend");
    backend.parse(prm);
    prm.leave_subsection();
    if (backend.single_precision)
      {
        for (unsigned int i = 0; i < materials.size(); ++i)
          if (materials[i].model == MaterialModel::user_defined)
            parameter_error("Backend/Precision", "float cannot run material '" + material_names[i] + "': its model '" +
                                        material_models[i] + "' is defined outside the library and steps in "
                                        "double; the allowed value is: double.");
      }

    if (method_auto)
      {
        if (bodies.empty())
          parameter_error("Solver/Method", "auto measures the scene's resolution across its bodies (Material points/Body i); "
                                "a scene whose points come from a FEM file has none: set the method (Method = as "
                                "set).");
        double extent = 0;
        for (unsigned int d = 0; d < dim; ++d)
          extent = std::max(extent, bodies_hi[d] - bodies_lo[d]);
        bool hencky_allowed = true;
        for (const MaterialParameters<double> &m : materials)
          hencky_allowed = hencky_allowed && m.model != MaterialModel::user_defined;
        MethodChoice choice;
        try
          {
            // CPDI's domains reach beyond a rank's ghost cells and the kept nodes (Solver/Shape function);
            const bool one_rank = !dealii::Utilities::MPI::job_supports_mpi() ||
                                  dealii::Utilities::MPI::n_mpi_processes(MPI_COMM_WORLD) == 1;
            // the cubic B-spline GIMP's reaches two cells out: one rank, and blocks of 2 cells or more (CPU)
            const bool bspline3_gimp_allowed =
              one_rank && (active_block_cells == 0 || (active_block_cells >= 2 && backend.name != "cuda"));
            choice = choose_method(method_scene, extent / cell_size, method_tolerance, backend.name == "cuda",
                                   hencky_allowed, dim, one_rank && active_block_cells == 0, bspline3_gimp_allowed);
          }
        catch (const std::invalid_argument &e)
          {
            parameter_error("Solver/Method tolerance", std::string(e.what()) + " Raise the tolerance, refine the grid (Grid/Cell "
                                                                    "size), or set the method (Method = as set).");
          }
        const MethodSettings &m = choice.method;
        shape_function          = m.shape;
        domain_update           = m.domain_update;
        apic                    = m.affine;
        affine_matrix           = m.affine_matrix;
        flip_fraction           = m.flip_fraction;
        for (MaterialParameters<double> &material : materials)
          if (material.model != MaterialModel::user_defined)
            material.elastic_law = m.hencky ? ElasticLaw::hencky : ElasticLaw::jaumann_rate;
        method_choice_report = choice.reason;
      }
    if (backend.name == "cuda")
      for (unsigned int i = 0; i < materials.size(); ++i)
        {
          if (materials[i].model == MaterialModel::user_defined)
            parameter_error("Backend/Backend", "cuda cannot run material '" + material_names[i] + "': its model '" +
                                      material_models[i] + "' is defined outside the library and runs on the "
                                      "CPU backend only (Backend = cpu).");
        }

    prm.enter_subsection("Resources");
    memory_limit = prm.get_double("Memory limit");
    prm.leave_subsection();
    check_particle_fields(*this);
    check_run_size(*this);
  }

  std::vector<std::string> Parameters::state_variable_names() const
  {
    std::vector<std::string> names;
    for (const MaterialParameters<double> &m : materials)
      if (m.user_model != nullptr)
        {
          const std::vector<StateVariable> variables = m.user_model->state_variables();
          for (std::size_t k = 0; k < variables.size(); ++k)
            if (k == names.size())
              names.push_back(variables[k].name);
            else if (names[k] != variables[k].name)
              names[k] = "state_variable_" + std::to_string(k); // two models, two meanings
        }
    if (apic) // APIC's affine matrix, after the models' own (affine_state_variable())
      for (unsigned int a = 0; a < dim; ++a)
        for (unsigned int b = 0; b < dim; ++b)
          names.push_back(std::string("apic_C_") + "xyz"[a] + "xyz"[b]);
    if (tracks_corners()) // CPDI2q's corners, last (corner_state_variable())
      for (unsigned int c = 0; c < 4; ++c)
        for (unsigned int d = 0; d < dim; ++d)
          names.push_back("cpdi2q_corner" + std::to_string(c + 1) + "_d" + "xyz"[d]);
    return names;
  }

  int Parameters::affine_state_variable() const
  {
    const int corners = tracks_corners() ? 4 * static_cast<int>(dim) : 0;
    return apic ? static_cast<int>(state_variable_names().size()) - static_cast<int>(dim * dim) - corners : -1;
  }

  int Parameters::corner_state_variable() const
  {
    return tracks_corners() ? static_cast<int>(state_variable_names().size()) - 4 * dim : -1;
  }

  std::vector<double> Parameters::initial_state_variables(const unsigned int material) const
  {
    std::vector<double> values(state_variable_names().size(), 0.0);
    if (const UserConstitutiveModel *user = materials.at(material).user_model)
      {
        const std::vector<StateVariable> variables = user->state_variables();
        for (std::size_t k = 0; k < variables.size(); ++k)
          values[k] = variables[k].initial_value;
      }
    return values;
  }

  namespace
  {
    // Edit distance of two names, case-insensitive (a typo's distance to what was meant).
    std::size_t edit_distance(const std::string &a, const std::string &b)
    {
      std::vector<std::size_t> row(b.size() + 1);
      for (std::size_t j = 0; j <= b.size(); ++j)
        row[j] = j;
      for (std::size_t i = 1; i <= a.size(); ++i)
        {
          std::size_t diagonal = row[0];
          row[0]               = i;
          for (std::size_t j = 1; j <= b.size(); ++j)
            {
              const std::size_t above = row[j];
              const bool same = std::tolower(static_cast<unsigned char>(a[i - 1])) ==
                                std::tolower(static_cast<unsigned char>(b[j - 1]));
              row[j]   = std::min({row[j] + 1, row[j - 1] + 1, diagonal + (same ? 0 : 1)});
              diagonal = above;
            }
        }
      return row[b.size()];
    }

    // For deal.II's messages of an undeclared entry or subsection ("No entry with name <X>",
    // "no such subsection to be entered: X"): the declared entries (as 'Section/Entry') or
    // subsections whose name is closest to X, within a third of its length; empty otherwise.
    std::string closest_declared_name(const ParameterHandler &prm, const std::string &message)
    {
      std::string unknown;
      bool        subsection = false;
      if (const std::size_t at = message.find("No entry with name <"); at != std::string::npos)
        unknown = message.substr(at + 20, message.find('>', at + 20) - (at + 20));
      else if (const std::size_t at = message.find("no such subsection to be entered: "); at != std::string::npos)
        {
          unknown    = dealii::Utilities::trim(message.substr(at + 34));
          subsection = true;
        }
      if (unknown.empty())
        return "";
      std::ostringstream listing;
      prm.print_parameters(listing, ParameterHandler::ShortPRM);
      std::set<std::string> candidates;
      for (const std::string &path : check_parameter_text(listing.str()))
        {
          std::vector<std::string> parts = dealii::Utilities::split_string_list(path, '/');
          if (!subsection)
            candidates.insert(path);
          else
            for (std::size_t k = 0; k + 1 < parts.size(); ++k)
              candidates.insert(parts[k]);
        }
      std::size_t best = unknown.size() / 3 + 1;
      std::string found;
      for (const std::string &candidate : candidates)
        {
          const std::string name     = subsection ? candidate : candidate.substr(candidate.rfind('/') + 1);
          const std::size_t distance = edit_distance(unknown, name);
          if (distance < best)
            {
              best  = distance;
              found = "'" + candidate + "'";
            }
          else if (distance == best && !found.empty() && found.size() < 400)
            found += " or '" + candidate + "'";
        }
      return found;
    }

    // The two passes of a read: the first finds the dimension, the number of bodies and the
    // material names (everything else skipped), the second declares every entry for them and
    // rejects unknown ones. parse(prm, skip_undefined) reads the input into prm.
    template <typename Parse>
    Parameters read_in_two_passes(Parse &&parse, const std::vector<ParameterSection> &sections)
    {
      ParameterHandler layout;
      declare_layout(layout);
      parse(layout, true);
      const unsigned int dim = layout.get_integer("Dimension");
      layout.enter_subsection("Material points");
      const unsigned int n_bodies = layout.get_integer("Number of bodies");
      layout.leave_subsection();
      layout.enter_subsection("Materials");
      const std::vector<std::string> names = dealii::Utilities::split_string_list(layout.get("Names"), ',');
      layout.leave_subsection();

      ParameterHandler prm;
      Parameters::declare(prm, dim, n_bodies, names);
      for (const ParameterSection &section : sections)
        section.declare(prm, dim);
      try
        {
          parse(prm, false);
        }
      catch (const dealii::ExceptionBase &e)
        {
          std::ostringstream info;
          e.print_info(info);
          const std::string suggestion = closest_declared_name(prm, info.str());
          if (suggestion.empty())
            throw;
          std::string message = dealii::Utilities::trim(info.str());
          if (!message.empty() && message.back() != '.')
            message += '.';
          AssertThrow(false, ExcMessage(message + " Did you mean " + suggestion +
                                        "? (dealii-mpm --print-parameters " + std::to_string(dim) +
                                        " lists every entry.)"));
        }
      Parameters parameters;
      parameters.parse(prm);
      for (const ParameterSection &section : sections)
        section.parse(prm, parameters);
      return parameters;
    }
  } // namespace

  Parameters read_parameters(const std::string &filename, const std::vector<ParameterSection> &sections)
  {
    {
      std::ifstream in(filename);
      AssertThrow(in, ExcMessage("Cannot open the parameter file '" + filename + "'."));
    }
    const std::optional<std::set<std::string>> set_entries = check_parameter_file(filename);
    Parameters parameters = read_in_two_passes([&](ParameterHandler &prm, const bool skip_undefined) {
      prm.parse_input(filename, "", skip_undefined, /*assert_mandatory_entries_are_found=*/false);
    }, sections);
    if (set_entries)
      check_given_subsections(parameters, *set_entries);
    return parameters;
  }

  Parameters parameters_from_string(const std::string &text, const std::vector<ParameterSection> &sections)
  {
    const std::set<std::string> set_entries = check_parameter_text(text);
    Parameters parameters = read_in_two_passes([&](ParameterHandler &prm, const bool skip_undefined) {
      prm.parse_input_from_string(text, "", skip_undefined);
    }, sections);
    check_given_subsections(parameters, set_entries);
    return parameters;
  }

  void print_parameters(std::ostream &out, const unsigned int dim, const std::string &style,
                        const std::vector<ParameterSection> &sections)
  {
    ParameterHandler prm;
    Parameters::declare(prm, dim, 1, {"soil"});
    for (const ParameterSection &section : sections)
      section.declare(prm, dim);
    // The listing of a 3D run must read as one: a copy of it runs in the dimension it was printed for.
    prm.set("Dimension", static_cast<long int>(dim));
    const ParameterHandler::OutputStyle s =
      style == "json" ? ParameterHandler::JSON : (style == "description" ? ParameterHandler::Description :
                                                                          ParameterHandler::PRM);
    prm.print_parameters(out, s);
  }
} // namespace mpm
