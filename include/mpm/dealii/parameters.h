// Run-time parameters of a dealii-mpm run, read from a deal.II parameter file.
// Every entry is declared with a pattern and a documentation string in
// parameters.cc; the executable prints them all with --print-parameters.
#pragma once

#include <mpm/core/material/material.h>
#include <mpm/core/shape_functions.h>
#include <mpm/core/step.h>
#include <mpm/fem/prefailure_parameters.h>
#include <mpm/fields/gaussian_random_field.h>

#include <deal.II/base/parameter_handler.h>

#include <array>
#include <map>
#include <string>
#include <vector>

namespace mpm
{
  enum class BoundaryType
  {
    free,      // no constraint
    no_slip,   // every velocity component zero
    free_slip, // normal velocity component zero (roller)
    friction   // rigid wall with Coulomb friction, unilateral contact (wall_friction.h)
  };

  struct BodyParameters
  {
    std::string                        shape; // box | polygon | cylinder
    std::vector<double>                lower, upper;
    std::vector<std::array<double, 2>> polygon; // (horizontal, vertical) pairs
    std::array<double, 2>              axis{};  // cylinder: (x, y) of its vertical axis
    double                             radius = 0;
    unsigned int                       points_per_direction;
    double                             density;
    std::vector<double>                velocity;
    std::string                        material;
    std::string                        initial_stress; // none | geostatic
    double                             k0;
  };

  struct Parameters
  {
    unsigned int dim = 2;

    // Grid
    std::vector<double> lower, upper;
    double              cell_size;
    int                 active_block_cells = 0; // Nodes = near material: block edge in cells; 0: all nodes
    int                 cells_per_grid_cell = 1; // edge of deal.II's cells in MPM cells
    std::array<BoundaryType, 6> boundary{}; // by boundary id: x min, x max, y min, y max, z min, z max
    double                      friction_coefficient = 0; // mu of every face of type friction

    // Solver
    double       end_time;
    UpdateScheme scheme;
    ShapeFunction shape_function;
    DomainUpdate domain_update;
    bool         adaptive_time_step;
    double       cfl;
    double       fixed_time_step;
    double       damping;
    LocalDampingForm damping_form;
    double       damping_threshold; // m/s
    double       flip_fraction;
    // Solver/FLIP at fixed nodes = velocity change (StepSettings::flip_fixed_velocity_change)
    bool         flip_fixed_velocity_change = false;
    // Solver/Velocity transfer = APIC or TPIC: an affine transfer, C_p in the last dim x dim state
    // variables, computed as affine_matrix says
    bool         apic          = false;
    // Solver/Method = auto: the pick and why, for the log (empty: Method = as set)
    std::string  method_choice_report;
    AffineMatrix affine_matrix = AffineMatrix::velocity_gradient;
    std::vector<double> gravity;
    double       gravity_ramp_time;
    double       plasticity_start_time;
    bool         pressure_averaging; // cell-wise volume-weighted pressure averaging
    unsigned int max_steps;
    double       max_predicted_steps = 1e9; // refuse a first time step predicting more (guards.h)

    // Materials, in the order of their names; bodies refer to them by index.
    std::vector<std::string>                material_names;
    std::vector<std::string>                material_models;
    std::vector<MaterialParameters<double>> materials;
    // Random field of the parameter named by materials[m].field_parameter (core units:
    // Pa, rad), mean = the material's own value.
    std::vector<RandomFieldParameters>      material_fields;
    // Per material: the largest fraction of its points whose field value may be raised to
    // the floor (1e-3 of the mean) before the run is refused (Random field/Maximum clipped fraction).
    std::vector<double>                     material_field_max_clipped;
    std::vector<BodyParameters>             bodies;
    std::vector<unsigned int>               body_material; // index into materials

    // Output
    std::string  output_directory;
    double       output_interval;
    bool         write_grid_fields;
    bool         write_particles;
    unsigned int history_every;
    double       progress_interval;
    bool         write_particle_table;
    std::vector<std::string> particle_fields; // Output/Particle fields: those written to the .vtu (empty: all)
    std::string  output_compression;   // zlib level of the .vtu files: "best speed", ...
    bool         output_in_background; // compress and write files on a background thread
    unsigned int output_files_per_rank; // .vtu pieces per rank and output, written in parallel
    unsigned int max_outputs = 10000;   // warn of more outputs than this; 0 = no warning

    // Resources (guards.h)
    double memory_limit = 0; // GB for the whole run; 0 = each node's available memory

    // Checkpoint (doc/checkpoints.md)
    unsigned int checkpoint_step_interval = 0;    // steps between checkpoints; 0 = none by steps
    double       checkpoint_wall_interval = 0;    // wall-clock minutes between checkpoints; 0 = none
    unsigned int checkpoint_keep          = 2;    // newest checkpoints kept
    std::string  checkpoint_directory;            // "" = <Output/Directory>/checkpoints
    bool         checkpoint_at_end        = false; // one more at the end of the run

    // Parallel runs (doc/performance.md, MPI)
    double resort_distance;        // re-sort at this fraction of the safe distance outside a home cell
    double load_balance_threshold; // repartition when max/mean work per rank exceeds it; 0 = never
    double point_weight;           // work of one point relative to one empty cell

    // Not a prm entry: the materials' strengths are the prm's divided by this (a pre-failure
    // analysis's hand-over sets it, fem/continuation.cc). Checkpoints record it, and a resumed
    // run must have the same (--resume of such a scene skips the FEM and sets it from there).
    double strength_divisor = 1;

    // Initial state: "prm bodies" (Material points) or "FEM file" (fem_state_file.h)
    std::string  initial_state_source = "prm bodies";
    std::string  fem_file;
    std::string  fem_placement = "quadrature points"; // or "lattice"
    unsigned int fem_points_per_direction = 2;
    int          fem_projection_degree    = -1;
    // Damped steps at t = 0 until the points rest in the MPM's own equilibrium (Simulator)
    bool         equilibrate                 = false;
    double       equilibration_damping       = 0.8;
    double       equilibration_tolerance     = 1e-6; // largest point speed / sqrt(|g| H)
    unsigned int equilibration_maximum_steps = 100000;
    // FEM material_id -> (index into materials, density)
    std::map<unsigned int, std::pair<unsigned int, double>> fem_materials;

    // The FEM stage before the MPM (subsection Pre-failure analysis; mpm/fem/)
    fem::PrefailureParameters prefailure;

    // Backend
    std::string backend;
    int         sort_interval = 20; // cuda: steps between re-sorts of the points on the device
    bool        queue_steps   = true; // cuda, one rank: steps queued before the last one ends
    bool        single_precision = false; // Backend/Precision = float: points, nodes and step in float

    // The state variables every point of the run carries (user_model.h): their names, the
    // longest list the materials' models declare (where two models name variable k
    // differently: state_variable_k), and the values the points of material m start with
    // (the model's own initial values, zero beyond its list).
    std::vector<std::string> state_variable_names() const;
    std::vector<double>      initial_state_variables(unsigned int material) const;
    // Velocity transfer = APIC: the index of the first of the dim x dim state variables that hold
    // each point's affine matrix (after the models' own); -1 otherwise.
    int affine_state_variable() const;
    // Shape function = CPDI2q: the index of the first of the 4 x dim state variables that hold each
    // point's corners (their offsets from the initial rectangle; after the affine matrix); -1 otherwise.
    int corner_state_variable() const;

    // Declares every entry for a given dimension, number of bodies and material names.
    static void declare(dealii::ParameterHandler &prm, unsigned int dim, unsigned int n_bodies,
                        const std::vector<std::string> &material_names);
    // Reads declared entries and checks the combinations a pattern cannot express.
    void parse(dealii::ParameterHandler &prm);
  };

  // Two-pass read of a parameter file: the first pass finds the dimension, the number
  // of bodies and the material names, the second declares and reads everything,
  // rejecting unknown entries. Throws with a message naming the offending entry.
  Parameters read_parameters(const std::string &filename);
  // The same from the text of a parameter file (a program that writes its scene in C++).
  Parameters parameters_from_string(const std::string &text);

  // Prints every entry with its default and documentation (for --print-parameters).
  void print_parameters(std::ostream &out, unsigned int dim, const std::string &style);
} // namespace mpm
