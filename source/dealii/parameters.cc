#include <mpm/dealii/guards.h>
#include <mpm/dealii/parameter_error.h>
#include <mpm/dealii/material_library.h>
#include <mpm/dealii/material_points.h>
#include <mpm/dealii/method_choice.h>
#include <mpm/dealii/parameters.h>

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

  namespace
  {
    const char *axis_names[3] = {"x", "y", "z"};

    // The built-in models' names for messages (material_family.h).
    const std::string any_built_in_model   = built_in_model_names([](auto) { return true; });
    const std::string models_with_strength =
      built_in_model_names([](auto member) { return has_friction_strength<decltype(member)>(); });

    std::string zeros(const unsigned int dim, const double last = 0)
    {
      std::string s;
      for (unsigned int d = 0; d < dim; ++d)
        s += (d ? ", " : "") + dealii::Utilities::to_string(d + 1 == dim ? last : 0.0);
      return s;
    }

    std::string ones(const unsigned int dim)
    {
      std::string s;
      for (unsigned int d = 0; d < dim; ++d)
        s += d ? ", 1" : "1";
      return s;
    }

    Patterns::List point_pattern(const unsigned int dim)
    {
      return Patterns::List(Patterns::Double(), dim, dim, ",");
    }

    // The first two edges of a closed polygon that meet other than at the vertex they share
    // (edge k runs from vertex k to vertex k + 1, the last back to vertex 0), or {-1, -1}: the
    // points fill a polygon by the even-odd rule, so a polygon that crosses itself (vertices in
    // the wrong order) leaves holes where the two sides overlap.
    std::pair<int, int> crossing_edges(const std::vector<std::array<double, 2>> &v)
    {
      const int  n      = static_cast<int>(v.size());
      const auto orient = [](const std::array<double, 2> &a, const std::array<double, 2> &b,
                             const std::array<double, 2> &c) {
        const double cross = (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]);
        return (cross > 0) - (cross < 0);
      };
      const auto on_segment = [](const std::array<double, 2> &a, const std::array<double, 2> &b,
                                 const std::array<double, 2> &c) { // c on the line ab: within its box?
        return std::min(a[0], b[0]) <= c[0] && c[0] <= std::max(a[0], b[0]) && std::min(a[1], b[1]) <= c[1] &&
               c[1] <= std::max(a[1], b[1]);
      };
      for (int k = 0; k < n; ++k)
        for (int m = k + 1; m < n; ++m)
          {
            const auto &a = v[k], &b = v[(k + 1) % n], &c = v[m], &d = v[(m + 1) % n];
            const int   o1 = orient(a, b, c), o2 = orient(a, b, d), o3 = orient(c, d, a), o4 = orient(c, d, b);
            const bool  adjacent = m == k + 1 || (k == 0 && m == n - 1);
            if (adjacent)
              {
                // Neighbours share a vertex; they overlap only if they fold back along one line.
                const auto &shared = m == k + 1 ? b : a, &far_k = m == k + 1 ? a : b, &far_m = m == k + 1 ? d : c;
                if (orient(far_k, shared, far_m) == 0 &&
                    (far_m[0] - shared[0]) * (far_k[0] - shared[0]) + (far_m[1] - shared[1]) * (far_k[1] - shared[1]) > 0)
                  return {k, m};
                continue;
              }
            if ((o1 != o2 && o3 != o4) || (o1 == 0 && on_segment(a, b, c)) || (o2 == 0 && on_segment(a, b, d)) ||
                (o3 == 0 && on_segment(c, d, a)) || (o4 == 0 && on_segment(c, d, b)))
              return {k, m};
          }
      return {-1, -1};
    }

    // The numbers of a list entry. The pattern has checked their form, but not their range: a
    // value such as 1e-400 matches Patterns::Double and still does not convert.
    std::vector<double> to_doubles(const std::string &entry, const std::string &text)
    {
      std::vector<double> values;
      for (const std::string &item : dealii::Utilities::split_string_list(text, ','))
        {
          try
            {
              values.push_back(dealii::Utilities::string_to_double(item));
            }
          catch (...)
            {
              parameter_error(entry, "'" + item + "' is not a finite double-precision number (magnitudes from about "
                          "2.2e-308 to 1.8e308, or 0).");
            }
        }
      return values;
    }

    // where: the subsection path of the entry, for the message.
    std::vector<double> get_point(ParameterHandler &prm, const std::string &entry, const std::string &where)
    {
      return to_doubles(where + entry, prm.get(entry));
    }

    std::string join(const std::vector<std::string> &items)
    {
      std::string s;
      for (const std::string &item : items)
        s += (s.empty() ? "" : ", ") + item;
      return s;
    }


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
  } // namespace

  void Parameters::declare(ParameterHandler &prm, const unsigned int dim, const unsigned int n_bodies,
                           const std::vector<std::string> &material_names)
  {
    declare_layout(prm);

    prm.enter_subsection("Grid");
    prm.declare_entry("Lower corner", zeros(dim), point_pattern(dim),
                      "Lower corner of the background grid, one coordinate per dimension (m).");
    prm.declare_entry("Upper corner", ones(dim), point_pattern(dim),
                      "Upper corner of the background grid (m). Each extent must be a multiple of the cell size.");
    prm.declare_entry("Cell size", "0.1", Patterns::Double(0),
                      "Edge length h of the square/cubic grid cells (m), the same in every direction.");
    prm.declare_entry("Nodes", "all", Patterns::Selection("all|near material"),
                      "Which nodes of the grid the step keeps and updates. all: every node of the box. near "
                      "material: only those of the blocks of Active block size^dim cells that hold a material "
                      "point or touch such a block, chosen again whenever a point has moved far enough to need "
                      "others; cost and memory then follow the material, not the box (the results are the same: "
                      "bit for bit on the CPU, to round-off on the GPU). The grid files then show only the cells "
                      "with mass, and on one rank deal.II's grid of the whole box is not built. The kept nodes are "
                      "numbered as the box around them where that box holds at most twice the kept blocks (no "
                      "lookup per node: as fast as every node of a box that size), else through a table with "
                      "one entry per block of nodes (no array over the whole box, so the box can be far larger "
                      "than the memory its nodes would take). On several ranks (Backend = cpu) deal.II's grid is "
                      "fine only within two blocks of the points (coarse elsewhere, refined as they spread), the "
                      "step visits only the kept nodes, and the partition weighs only the cells with points; "
                      "nothing is kept per cell of the box (about 6 bytes per block). With Backend = cuda on "
                      "several ranks each rank keeps every node of its part of the grid.");
    prm.declare_entry("Active block size", "4", Patterns::Integer(1, 64),
                      "Nodes = near material: edge of the blocks, in cells. Every cell within this many cells "
                      "of a point's cell is kept; larger blocks choose the nodes less often but keep more. The "
                      "cubic B-spline GIMP, whose stencil reaches two cells out, needs at least 2.");
    prm.declare_entry("Cells per deal.II cell", "1", Patterns::Integer(1, 16),
                      "Edge k of deal.II's cells of the background grid, in cells of Cell size: deal.II's grid has "
                      "k^dim times fewer cells, and its Q_k elements with equidistant nodes put a degree of "
                      "freedom at every node of the MPM grid, so the step, its nodes and its results are the "
                      "same. Building deal.II's grid (on several ranks before the first step) is then much "
                      "faster, and the partition among ranks moves whole deal.II cells. Each extent of the grid "
                      "must be a multiple of k cells.");
    prm.leave_subsection();

    prm.enter_subsection("Boundary conditions");
    for (unsigned int d = 0; d < dim; ++d)
      for (const std::string side : {"min", "max"})
        prm.declare_entry(std::string(axis_names[d]) + " " + side, "free",
                          Patterns::Selection("free|no-slip|free-slip|friction"),
                          std::string("Condition on the grid face ") + axis_names[d] + " = " + side +
                            " (boundary id " + std::to_string(2 * d + (side == std::string("max"))) +
                            "): free (points that cross it leave the grid and are removed), no-slip (all "
                            "velocity components zero), free-slip (roller: normal component zero) or friction "
                            "(a rigid wall with Coulomb friction, coefficient Friction coefficient: where "
                            "material presses on it, normal component zero and the tangential one braked; where "
                            "material moves away, nothing). The three walls also stop the points' centres "
                            "on the face.");
    prm.declare_entry("Friction coefficient", "0", Patterns::Double(0),
                      "Coulomb friction coefficient mu of every face set to friction: where material presses "
                      "on the wall, the tangential velocity of a wall node is reduced by mu times its normal "
                      "velocity into the wall, to rest at most. Must be > 0 where a face is friction "
                      "(for a wall without friction use free-slip).");
    prm.leave_subsection();

    prm.enter_subsection("Solver");
    prm.declare_entry("End time", "1", Patterns::Double(0), "Simulated end time (s).");
    prm.declare_entry("Update scheme", "MUSL", Patterns::Selection("MUSL|USL|USF"),
                      "Explicit update scheme: MUSL (modified update stress last, default), USL or USF.");
    prm.declare_entry("Shape function", "GIMP",
                      Patterns::Selection("linear|GIMP|quadratic B-spline|cubic B-spline|cubic B-spline GIMP|CPDI|"
                                          "CPDI2q"),
                      "Grid shape functions: linear (standard MPM), GIMP (generalised interpolation), "
                      "quadratic B-spline (C1, three nodes per direction; within half a cell of the grid's "
                      "faces it becomes linear, doc/theory.md), cubic B-spline (C2, four nodes per direction, "
                      "the same treatment at the faces; in MPI runs the points are re-sorted whenever one "
                      "leaves its cell), cubic B-spline GIMP (the cubic B-spline averaged over each point's "
                      "axis-aligned domain, five nodes per direction; with GIMP domain update = F_ii, det F or U "
                      "the domains follow the deformation), CPDI (the linear hats averaged over each point's "
                      "parallelogram or "
                      "parallelepiped domain, whose edges follow F, including its rotation and shear) or CPDI2q "
                      "(2D: the same over a quadrilateral whose four corners move with the grid's velocity). "
                      "CPDI and CPDI2q: one MPI rank, Grid/Nodes = all. Cubic B-spline GIMP: one MPI rank; "
                      "Grid/Nodes = near material needs Active block size >= 2.");
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

    prm.enter_subsection("Materials");
    prm.leave_subsection();
    for (const std::string &name : material_names)
      {
        prm.enter_subsection("Material " + name);
        prm.declare_entry("Model", "linear elastic", Patterns::Selection(material_model_names()),
                          "Constitutive model of this material, one of: " + material_model_names() + ".");
        prm.declare_entry("Elastic law", "Jaumann rate", Patterns::Selection("Jaumann rate|Hencky"),
                          "The elastic part of a built-in model at large strain. Jaumann rate: hypoelastic, the "
                          "stress rotated with the spin plus C : d_eps per step. Hencky: hyperelastic in "
                          "logarithmic strain (Kirchhoff stress = C : ln V_e), plasticity multiplicative with the "
                          "model's return mapping in principal logarithmic strains (doc/theory-plasticity.md). The "
                          "two agree at small strain. Both backends; not with models defined outside the "
                          "library.");
        prm.declare_entry("Disconnection volume ratio", "0", Patterns::Double(0),
                          "A point whose volume exceeds this multiple of its initial volume has lost contact "
                          "(a granular material's disconnected phase): it carries no stress and takes no part "
                          "in the pressure averaging, and compacted back below the ratio its stress starts again "
                          "from zero. Keeps points that a thin front has dilated to many times their volume from "
                          "taking a recompression's stress on that whole volume (doc/methods.md, \"Disconnected "
                          "points\"). 0 (the default): never; otherwise a ratio > 1, e.g. 2. The MPM step only "
                          "(not the FEM stage).");
        for (const auto &[model, plugin] : material_library())
          {
            prm.enter_subsection(model);
            plugin.declare_parameters(prm);
            prm.leave_subsection();
          }
        prm.enter_subsection("Random field");
        prm.declare_entry("Parameter", "none", Patterns::Selection("none|cohesion|friction angle|Young's modulus"),
                          "Material parameter that varies in space as a stationary Gaussian random field sampled at "
                          "the points; its mean is the value given in the model's subsection (cohesion and friction "
                          "angle need a plastic model). Cohesion keeps c_res/c, friction angle keeps phi - phi_res.");
        prm.declare_entry("Covariance", "gaussian", Patterns::Selection("gaussian|exponential"),
                          "gaussian: C(r) = s^2 exp(-sum (r_d/L_d)^2); exponential: C(r) = s^2 exp(-|r/L|).");
        prm.declare_entry("Correlation lengths", ones(dim), point_pattern(dim),
                          "Correlation length L_d along each axis (m, > 0).");
        prm.declare_entry("Standard deviation", "0", Patterns::Double(0),
                          "Standard deviation s, in the parameter's prm unit (Pa, degrees).");
        prm.declare_entry("Seed", "1", Patterns::Integer(0), "Seed of the random numbers (same seed, same field).");
        prm.declare_entry("Maximum clipped fraction", "0.01", Patterns::Double(0, 1),
                          "A Gaussian field can fall below zero: values below 1e-3 of the mean are raised to that "
                          "floor, which shifts the field's mean and distribution. The run is refused when more than "
                          "this fraction of the material's points are raised (a standard deviation large against "
                          "the mean: 1% of a Gaussian lies below mean - 2.33 standard deviations).");
        prm.leave_subsection();
        prm.leave_subsection();
      }

    prm.enter_subsection("Material points");
    for (unsigned int b = 1; b <= n_bodies; ++b)
      {
        prm.enter_subsection("Body " + std::to_string(b));
        prm.declare_entry("Shape", "box", Patterns::Selection("box|polygon|cylinder"),
                          "box: the points fill [Lower corner, Upper corner]. polygon: the points fill the polygon "
                          "given by 'Polygon vertices' in the (x, vertical) plane; in 3D it is extruded along y "
                          "between the y coordinates of Lower and Upper corner. cylinder (3D only): the points of "
                          "the box [Lower corner, Upper corner] within 'Radius' of the vertical line through "
                          "'Cylinder axis' (a column, or the quarter of one cut by the box).");
        prm.declare_entry("Lower corner", zeros(dim), point_pattern(dim), "Lower corner of the box (m).");
        prm.declare_entry("Upper corner", ones(dim), point_pattern(dim), "Upper corner of the box (m).");
        prm.declare_entry("Polygon vertices", "",
                          Patterns::List(Patterns::List(Patterns::Double(), 2, 2, ","), 0,
                                         Patterns::List::max_int_value, ";"),
                          "Vertices 'x1, v1; x2, v2; ...' of the polygon (at least 3), v the vertical "
                          "coordinate (y in 2D, z in 3D).");
        prm.declare_entry("Cylinder axis", "0, 0", Patterns::List(Patterns::Double(), 2, 2, ","),
                          "Shape = cylinder: the horizontal coordinates 'x, y' of the cylinder's vertical axis (m).");
        prm.declare_entry("Radius", "0", Patterns::Double(0), "Shape = cylinder: its radius (m), > 0.");
        prm.declare_entry("Points per cell direction", "2", Patterns::Integer(1, 10),
                          "Material points per cell along each direction (2 gives 2x2 in 2D, 2x2x2 in 3D).");
        prm.declare_entry("Density", "1000", Patterns::Double(0), "Mass density (kg/m^3, > 0).");
        prm.declare_entry("Initial velocity", zeros(dim), point_pattern(dim), "Initial velocity (m/s).");
        prm.declare_entry("Material", material_names.front(), Patterns::Anything(),
                          "Name of this body's material, one of the names in Materials/Names.");
        prm.declare_entry("Initial stress", "none", Patterns::Selection("none|geostatic"),
                          "none: stress free. geostatic: vertical stress -|g| times the weight per unit area of "
                          "the material of all bodies above the point (sum of density x thickness; stacked "
                          "bodies load the ones below), horizontal stresses K0 of this body times it.");
        prm.declare_entry("K0", "0.5", Patterns::Double(0), "Lateral earth pressure coefficient for geostatic.");
        prm.leave_subsection();
      }
    prm.leave_subsection();

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

  void Parameters::parse(ParameterHandler &prm)
  {
    dim = prm.get_integer("Dimension");

    prm.enter_subsection("Grid");
    lower     = get_point(prm, "Lower corner", "Grid/");
    upper     = get_point(prm, "Upper corner", "Grid/");
    cell_size = prm.get_double("Cell size");
    if (!(cell_size > 0))
      parameter_error("Grid/Cell size", "must be > 0, got " + prm.get("Cell size") + ".");
    for (unsigned int d = 0; d < dim; ++d)
      {
        if (!(upper[d] > lower[d]))
          parameter_error("Grid/Upper corner", std::string("must exceed Lower corner in ") + axis_names[d] + ".");
        const double n = (upper[d] - lower[d]) / cell_size;
        if (std::abs(n - std::round(n)) > 1e-8 * std::max(1.0, n))
          parameter_error("Grid/Cell size", std::string("the extent in ") + axis_names[d] + " (" +
                                   dealii::Utilities::to_string(upper[d] - lower[d]) +
                                   " m) is not a whole number of cells of size " + prm.get("Cell size") + ".");
      }
    active_block_cells = prm.get("Nodes") == "near material" ? prm.get_integer("Active block size") : 0;
    cells_per_grid_cell = prm.get_integer("Cells per deal.II cell");
    for (unsigned int d = 0; d < dim; ++d)
      {
        const long n = std::lround((upper[d] - lower[d]) / cell_size);
        if (n % cells_per_grid_cell != 0)
          parameter_error("Grid/Cells per deal.II cell",
               "must divide the number of cells along every direction; " + std::string(axis_names[d]) + " has " +
                 std::to_string(n) + " cells, not a multiple of " + std::to_string(cells_per_grid_cell) + ".");
      }
    prm.leave_subsection();

    prm.enter_subsection("Boundary conditions");
    for (unsigned int d = 0; d < dim; ++d)
      for (unsigned int side = 0; side < 2; ++side)
        {
          const std::string v = prm.get(std::string(axis_names[d]) + (side ? " max" : " min"));
          boundary[2 * d + side] = v == "no-slip"   ? BoundaryType::no_slip :
                                   v == "free-slip" ? BoundaryType::free_slip :
                                   v == "friction"  ? BoundaryType::friction :
                                                      BoundaryType::free;
        }
    friction_coefficient = prm.get_double("Friction coefficient");
    for (unsigned int id = 0; id < 2 * dim; ++id)
      if (boundary[id] == BoundaryType::friction && !(friction_coefficient > 0))
        parameter_error("Boundary conditions/Friction coefficient",
             std::string("must be > 0 where a face is friction (") + axis_names[id / 2] + (id % 2 ? " max" : " min") +
               " is); for a wall without friction set that face to free-slip.");
    prm.leave_subsection();

    prm.enter_subsection("Solver");
    end_time = prm.get_double("End time");
    const std::string s = prm.get("Update scheme");
    scheme = s == "USL" ? UpdateScheme::usl : (s == "USF" ? UpdateScheme::usf : UpdateScheme::musl);
    const std::string shape = prm.get("Shape function");
    shape_function = shape == "GIMP"               ? ShapeFunction::gimp :
                     shape == "quadratic B-spline" ? ShapeFunction::bspline2 :
                     shape == "cubic B-spline"     ? ShapeFunction::bspline3 :
                     shape == "cubic B-spline GIMP" ? ShapeFunction::bspline3_gimp :
                     shape == "CPDI"               ? ShapeFunction::cpdi :
                     shape == "CPDI2q"             ? ShapeFunction::cpdi2q : ShapeFunction::linear;
    const bool cpdi_family = shape_function == ShapeFunction::cpdi || shape_function == ShapeFunction::cpdi2q;
    if (shape_function == ShapeFunction::cpdi2q && dim != 2)
      parameter_error("Solver/Shape function", "CPDI2q is two-dimensional (its domains are quadrilaterals); in 3D use CPDI, "
                                    "whose parallelepipeds follow F.");
    const std::string du = prm.get("GIMP domain update");
    domain_update = du == "det F" ? DomainUpdate::det_F :
                    du == "F_ii"  ? DomainUpdate::stretch :
                    du == "U"     ? DomainUpdate::U : DomainUpdate::none;
    if (shape_function != ShapeFunction::gimp && shape_function != ShapeFunction::bspline3_gimp &&
        domain_update != DomainUpdate::none)
      parameter_error("Solver/GIMP domain update", "'" + du + "' needs Shape function = GIMP or cubic B-spline GIMP; with "
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
    if (transfer == "APIC" &&
        (shape_function == ShapeFunction::gimp || shape_function == ShapeFunction::bspline3_gimp || cpdi_family))
      parameter_error("Solver/Velocity transfer", "APIC needs Shape function = linear, quadratic B-spline or cubic B-spline "
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

    prm.enter_subsection("Materials");
    material_names = dealii::Utilities::split_string_list(prm.get("Names"), ',');
    prm.leave_subsection();
    for (unsigned int i = 0; i < material_names.size(); ++i)
      for (unsigned int j = 0; j < i; ++j)
        if (material_names[i] == material_names[j])
          parameter_error("Materials/Names", "the name '" + material_names[i] + "' appears twice.");
    for (const std::string &name : material_names)
      {
        prm.enter_subsection("Material " + name);
        const std::string model = prm.get("Model");
        prm.enter_subsection(model);
        try
          {
            materials.push_back(material_library().at(model).parse_parameters(prm));
          }
        catch (const dealii::ExceptionBase &e)
          {
            // A model's checks say "Entry 'NAME' what": named here by the entry's whole path.
            std::ostringstream info;
            e.print_info(info);
            const std::string what    = dealii::Utilities::trim(info.str());
            const std::string section = "Material " + name + "/" + model;
            const std::size_t closing = what.find("' ", 7);
            if (what.rfind("Entry '", 0) == 0 && closing != std::string::npos)
              parameter_error(section + "/" + what.substr(7, closing - 7), what.substr(closing + 2));
            parameter_error(section, what);
          }
        prm.leave_subsection();
        if (prm.get("Elastic law") == "Hencky")
          {
            if (materials.back().model == MaterialModel::user_defined)
              parameter_error("Material " + name + "/Elastic law", "Hencky needs a built-in model (" + any_built_in_model + "); '" + model + "' is defined outside "
                                                        "the library and gets only strain and spin increments.");
            materials.back().elastic_law = ElasticLaw::hencky;
          }
        {
          const double ratio = prm.get_double("Disconnection volume ratio");
          if (ratio != 0 && !(ratio > 1))
            parameter_error("Material " + name + "/Disconnection volume ratio",
                 "must be 0 (never) or a ratio of volumes greater than 1; got " + prm.get("Disconnection volume ratio") +
                   ".");
          materials.back().disconnection_volume_ratio = ratio;
        }
        if (const UserConstitutiveModel *user = materials.back().user_model)
          {
            const std::vector<StateVariable> variables = user->state_variables();
            if (variables.size() > static_cast<std::size_t>(max_state_variables))
              parameter_error("Material " + name + "/Model", "the model '" + model + "' declares " +
                                                    std::to_string(variables.size()) + " state variables; at most " +
                                                    std::to_string(max_state_variables) + " are allowed.");
            for (const StateVariable &v : variables)
              if (v.name.empty() || v.name.find_first_of(" ,") != std::string::npos)
                parameter_error("Material " + name + "/Model", "the model '" + model + "' declares a state variable named '" +
                                                      v.name + "'; names must be non-empty, without spaces or commas "
                                                      "(they name output fields).");
          }

        // The random field: its mean is the material's own value of the parameter.
        prm.enter_subsection("Random field");
        const std::string  field = prm.get("Parameter");
        const std::string  where = "Material " + name + "/Random field/";
        MaterialParameters<double> &m = materials.back();
        RandomFieldParameters       rf;
        rf.covariance         = prm.get("Covariance") == "exponential" ? Covariance::exponential : Covariance::gaussian;
        rf.correlation_length = get_point(prm, "Correlation lengths", where);
        rf.standard_deviation = prm.get_double("Standard deviation");
        rf.seed               = prm.get_integer("Seed");
        material_field_max_clipped.push_back(prm.get_double("Maximum clipped fraction"));
        for (const double L : rf.correlation_length)
          if (!(L > 0))
            parameter_error(where + "Correlation lengths", "every correlation length must be > 0.");
        const SofteningStrength<double> *strength = nullptr;
        with_built_in_model(m.model, [&](auto member) {
          strength = decltype(member)::strength(parameters_of<decltype(member)>(m));
        });
        if (field != "none" && m.model == MaterialModel::user_defined)
          parameter_error(where + "Parameter", "a random field needs a built-in model (" + any_built_in_model + "); '" + model +
                                                 "' is defined outside the library.");
        if (field == "cohesion" || field == "friction angle")
          {
            if (strength == nullptr)
              parameter_error(where + "Parameter", "'" + field + "' needs a model with c and phi (" + models_with_strength + "), "
                                        "not '" + model + "'.");
            m.field_parameter = field == "cohesion" ? FieldParameter::cohesion : FieldParameter::friction_angle;
            rf.mean           = field == "cohesion" ? strength->cohesion : strength->friction_angle;
            if (field == "friction angle")
              rf.standard_deviation *= M_PI / 180;
          }
        else if (field == "Young's modulus")
          {
            m.field_parameter = FieldParameter::youngs_modulus;
            rf.mean           = m.elastic.youngs_modulus;
          }
        material_fields.push_back(rf);
        prm.leave_subsection();

        prm.leave_subsection();
        material_models.push_back(model);
      }

    prm.enter_subsection("Initial state");
    initial_state.parse(prm, material_names, materials);
    prm.leave_subsection();
    if (initial_state.equilibrate && gravity_ramp_time > 0)
      parameter_error("Initial state/Equilibrate", "the equilibration holds gravity in full; it needs Solver/Gravity ramp "
                                        "time = 0 (a ramp after it would take the load off the state).");

    prm.enter_subsection("Material points");
    const unsigned int n_bodies = initial_state.source == "FEM file" ? 0 : prm.get_integer("Number of bodies");
    // The bodies' bounding box (Method = auto measures the resolution across it).
    std::vector<double> bodies_lo(dim, std::numeric_limits<double>::max()),
      bodies_hi(dim, std::numeric_limits<double>::lowest());
    for (unsigned int b = 1; b <= n_bodies; ++b)
      {
        const std::string where = "Material points/Body " + std::to_string(b) + "/";
        prm.enter_subsection("Body " + std::to_string(b));
        BodyParameters body;
        body.shape = prm.get("Shape");
        body.lower = get_point(prm, "Lower corner", where);
        body.upper = get_point(prm, "Upper corner", where);
        for (const std::string &vertex :
             dealii::Utilities::split_string_list(prm.get("Polygon vertices"), ';'))
          {
            const auto xy = to_doubles(where + "Polygon vertices", vertex);
            body.polygon.push_back({{xy[0], xy[1]}});
          }
        {
          const auto axis = to_doubles(where + "Cylinder axis", prm.get("Cylinder axis"));
          body.axis   = {{axis[0], axis[1]}};
          body.radius = prm.get_double("Radius");
        }
        body.points_per_direction = prm.get_integer("Points per cell direction");
        body.density              = prm.get_double("Density");
        body.velocity             = get_point(prm, "Initial velocity", where);
        body.material             = prm.get("Material");
        body.initial_stress       = prm.get("Initial stress");
        body.k0                   = prm.get_double("K0");
        prm.leave_subsection();

        if (!(body.density > 0))
          parameter_error(where + "Density", "must be > 0.");
        unsigned int material_index = material_names.size();
        for (unsigned int m = 0; m < material_names.size(); ++m)
          if (material_names[m] == body.material)
            material_index = m;
        if (material_index == material_names.size())
          parameter_error(where + "Material", "'" + body.material + "' is not one of Materials/Names (allowed: " +
                                     join(material_names) + ").");
        if (body.shape == "cylinder" && dim != 3)
          parameter_error(where + "Shape", "a cylinder (a vertical column) needs Dimension = 3; in 2D use box or polygon.");
        if (body.shape == "cylinder" && !(body.radius > 0))
          parameter_error(where + "Radius", "a cylinder needs a radius > 0.");
        if (body.shape == "polygon" && body.polygon.size() < 3)
          parameter_error(where + "Polygon vertices", "a polygon needs at least 3 vertices, got " +
                                             std::to_string(body.polygon.size()) + ".");
        if (body.shape == "polygon")
          {
            const auto [k, m] = crossing_edges(body.polygon);
            const int n = static_cast<int>(body.polygon.size());
            const auto edge = [n](const int e) {
              return "from vertex " + std::to_string(e + 1) + " to vertex " + std::to_string((e + 1) % n + 1);
            };
            if (k >= 0)
              parameter_error(where + "Polygon vertices",
                   "the polygon crosses itself: its edge " + edge(k) + " meets the edge " + edge(m) +
                     ". Give the vertices in order around the boundary (either direction), so that no two edges "
                     "cross or overlap.");
          }
        // The body must lie inside the grid: a point outside could never be used.
        std::vector<double> lo = body.lower, hi = body.upper;
        if (body.shape == "polygon")
          {
            lo[0] = hi[0] = body.polygon[0][0];
            lo[dim - 1] = hi[dim - 1] = body.polygon[0][1];
            for (const auto &v : body.polygon)
              {
                lo[0]       = std::min(lo[0], v[0]);
                hi[0]       = std::max(hi[0], v[0]);
                lo[dim - 1] = std::min(lo[dim - 1], v[1]);
                hi[dim - 1] = std::max(hi[dim - 1], v[1]);
              }
          }
        // The entry at fault: a polygon's vertices, or the box corner on the side that is wrong.
        const auto entry = [&body](const bool upper_side) {
          return body.shape == "polygon" ? std::string("Polygon vertices") :
                                           std::string(upper_side ? "Upper corner" : "Lower corner");
        };
        const auto number = [](const double x) { // 0.6, not 0.59999999999999998
          std::ostringstream out;
          out << std::setprecision(12) << x;
          return out.str();
        };
        for (unsigned int d = 0; d < dim; ++d)
          {
            if (!(hi[d] > lo[d]))
              parameter_error(where + entry(true), std::string(hi[d] < lo[d] ? "the upper corner lies below the lower one in " :
                                                                      "the body has no extent in ") +
                                          axis_names[d] + " (" + number(lo[d]) + " to " + number(hi[d]) + ").");
            if (lo[d] < lower[d] - 1e-12 || hi[d] > upper[d] + 1e-12)
              parameter_error(where + entry(hi[d] > upper[d] + 1e-12),
                   std::string("the body reaches outside the grid in ") + axis_names[d] + " ([" + number(lo[d]) +
                     ", " + number(hi[d]) + "] is not inside [" + number(lower[d]) + ", " + number(upper[d]) +
                     "]).");
          }
        if (body.shape == "cylinder")
          for (unsigned int d = 0; d < 2; ++d)
            {
              lo[d] = body.axis[d] - body.radius;
              hi[d] = body.axis[d] + body.radius;
            }
        for (unsigned int d = 0; d < dim; ++d)
          {
            bodies_lo[d] = std::min(bodies_lo[d], lo[d]);
            bodies_hi[d] = std::max(bodies_hi[d], hi[d]);
          }
        bodies.push_back(body);
        body_material.push_back(material_index);
      }
    prm.leave_subsection();

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
    if (shape_function == ShapeFunction::cpdi2q) // CPDI2q's corners, last (corner_state_variable())
      for (unsigned int c = 0; c < 4; ++c)
        for (unsigned int d = 0; d < dim; ++d)
          names.push_back("cpdi2q_corner" + std::to_string(c + 1) + "_d" + "xyz"[d]);
    return names;
  }

  int Parameters::affine_state_variable() const
  {
    const int corners = shape_function == ShapeFunction::cpdi2q ? 4 * static_cast<int>(dim) : 0;
    return apic ? static_cast<int>(state_variable_names().size()) - static_cast<int>(dim * dim) - corners : -1;
  }

  int Parameters::corner_state_variable() const
  {
    return shape_function == ShapeFunction::cpdi2q ? static_cast<int>(state_variable_names().size()) - 4 * dim : -1;
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
