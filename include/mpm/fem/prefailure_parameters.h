// The prm entries of the pre-failure FEM stage (subsection Pre-failure analysis): which
// analysis, the mesh, the boundary conditions, Newton's settings and the strength reduction.
// Declared and read with the rest of the parameter file (mpm::Parameters::prefailure);
// every entry's documentation is in prefailure_parameters.cc and doc/parameters.md.
#pragma once

#include <deal.II/base/parameter_handler.h>

#include <map>
#include <string>
#include <vector>

namespace mpm::fem
{
  enum class Analysis
  {
    none,              // no FEM stage: the MPM starts from the prm's bodies or the FEM file
    gravity_loading,   // elasto-plastic gravity loading in load steps
    k0_procedure,      // sigma_v from the overburden, sigma_h = K0 sigma_v, then an equilibrium step
    strength_reduction // the initial stresses, then c, tan(phi), tan(psi) divided by F until failure
  };

  enum class BoundaryCondition
  {
    free,  // no constraint
    roller, // the displacement normal to the (plane, axis-aligned) boundary fixed
    fixed,  // every displacement component fixed
    periodic // ids 2d and 2d + 1 (the bounding box's faces normal to axis d) tied to each other
  };

  struct PrefailureParameters
  {
    Analysis analysis = Analysis::none;
    // Strength reduction: how the stresses before the reduction are made.
    Analysis initial_stresses = Analysis::gravity_loading;

    // Mesh: "prm bodies" (the one body of Material points, a box or a polygon; extruded in 3D)
    // or "mesh file" (GridIn: Gmsh .msh, UCD .inp/.ucd, with the material ids of
    // Initial state/Materials).
    std::string  mesh = "prm bodies";
    std::string  mesh_file;
    double       cell_size          = 0; // m; 0 = the MPM's Grid/Cell size
    unsigned int global_refinements = 0;
    unsigned int degree             = 2; // FE_Q(degree)^dim
    // By boundary id (generated meshes: 0/1 x min/max, 2/3 the next axis, 4/5 z in 3D, 6 the
    // rest); ids not named are free.
    std::map<unsigned int, BoundaryCondition> boundary_conditions;

    // Newton
    unsigned int load_steps               = 4;
    unsigned int maximum_newton_iterations = 200;
    unsigned int maximum_initial_stiffness_iterations = 1000; // after a failed Newton; 0 = none
    double       initial_stiffness_tolerance          = 1e-5; // relative, as residual_tolerance
    double       residual_tolerance       = 1e-8; // relative to the full gravity load vector's norm
    bool         line_search              = true;
    std::string  linear_solver            = "direct"; // or "iterative" (GMRES + AMG)

    // K0 procedure: K0 of every material; < 0 = nu / (1 - nu) of each.
    double k0 = -1;

    // Strength reduction: F from minimum_factor upwards in steps of factor_increment, the step
    // halved where a factor fails, until it is below factor_tolerance; no failure up to
    // maximum_factor is reported as such.
    double minimum_factor   = 1;
    double maximum_factor   = 10;
    double factor_increment = 0.1;
    double factor_tolerance = 0.005;
    // Where the displacement of the F-displacement curve is read: the mesh vertex nearest to
    // this point; empty = the largest nodal displacement.
    std::vector<double> monitor_point;

    // After the analysis: the MPM run from its committed state (placement (a) of the
    // hand-over), with every strength divided by mpm_strength_factor, or by the strength
    // reduction's failing factor where mpm_strength_from_failure.
    bool   continue_with_mpm         = true;
    double mpm_strength_factor       = 1;
    bool   mpm_strength_from_failure = false;

    // Declares the subsection's entries for a dimension (defaults of the boundary conditions
    // depend on it).
    static void declare(dealii::ParameterHandler &prm, unsigned int dim);
    // Reads them (prm outside the subsection); throws naming the entry on bad input.
    void parse(dealii::ParameterHandler &prm, unsigned int dim);
  };

  std::string to_string(Analysis analysis);
} // namespace mpm::fem
