// Run-time parameters of a dealii-mpm run, read from a deal.II parameter file.
// Every entry is declared with a pattern and a documentation string in
// parameters.cc; the executable prints them all with --print-parameters.
#pragma once

#include <mpm/core/material/material.h>
#include <mpm/core/point_fields.h>
#include <mpm/core/shape/shape_family.h>
#include <mpm/core/step/settings.h>
#include <mpm/dealii/backend_settings.h>
#include <mpm/dealii/body_settings.h>
#include <mpm/dealii/checkpoint_settings.h>
#include <mpm/dealii/grid_settings.h>
#include <mpm/dealii/initial_state_settings.h>
#include <mpm/dealii/material_settings.h>
#include <mpm/dealii/output_settings.h>
#include <mpm/dealii/parallel_settings.h>
#include <mpm/fields/gaussian_random_field.h>

#include <deal.II/base/parameter_handler.h>

#include <array>
#include <functional>
#include <map>
#include <string>
#include <vector>

namespace mpm
{
  // The run's settings. Grid (with Boundary conditions), Materials and the bodies of Material points
  // are components that declare and parse their own subsections (grid_settings.h,
  // material_settings.h, body_settings.h); a part that needs only one takes that component.
  struct Parameters : GridSettings, MaterialSettings, BodySettings
  {
    unsigned int dim = 2;

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

    OutputSettings output; // Output

    // Resources (guards.h)
    double memory_limit = 0; // GB for the whole run; 0 = each node's available memory

    CheckpointSettings checkpoint; // Checkpoint (doc/checkpoints.md)
    ParallelSettings   parallel;   // Parallel: MPI runs (doc/performance.md, MPI)

    // Not a prm entry: the materials' strengths are the prm's divided by this (a pre-failure
    // analysis's hand-over sets it, run/prefailure_then_mpm.cc). Checkpoints record it, and a resumed
    // run must have the same (--resume of such a scene skips the FEM and sets it from there).
    double strength_divisor = 1;

    InitialStateSettings initial_state; // Initial state

    BackendSettings backend; // Backend

    // The fields every point of the run carries (point_fields.h): those of every run, and those
    // a physics module or a test asks for. Not read from the prm.
    PointFieldSet point_fields;

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
    // The shape function's domain corners are state variables (Cpdi2qShape::tracks_corners).
    bool tracks_corners() const;

    // Declares every entry for a given dimension, number of bodies and material names.
    static void declare(dealii::ParameterHandler &prm, unsigned int dim, unsigned int n_bodies,
                        const std::vector<std::string> &material_names);
    // Reads declared entries and checks the combinations a pattern cannot express.
    void parse(dealii::ParameterHandler &prm);
  };

  // A subsection of the same parameter file that a part of the program above this layer reads
  // for itself (the pre-failure FEM stage's: run/scene.h): declared beside the MPM's entries, so
  // that one file describes the whole scene, and parsed after them, with the MPM's parameters
  // to check its entries against. parse throws naming the entry on bad input.
  struct ParameterSection
  {
    std::function<void(dealii::ParameterHandler &prm, unsigned int dim)>           declare;
    std::function<void(dealii::ParameterHandler &prm, const Parameters &parameters)> parse;
  };

  // Two-pass read of a parameter file: the first pass finds the dimension, the number
  // of bodies and the material names, the second declares and reads everything (the MPM's
  // entries and those of `sections`), rejecting unknown entries. Throws with a message naming
  // the offending entry.
  Parameters read_parameters(const std::string &filename, const std::vector<ParameterSection> &sections = {});
  // The same from the text of a parameter file (a program that writes its scene in C++).
  Parameters parameters_from_string(const std::string &text, const std::vector<ParameterSection> &sections = {});

  // Prints every entry (the MPM's and those of `sections`) with its default and documentation
  // (for --print-parameters).
  // Puts the shape functions owned by `test` (shape_family.h) into Solver/Shape function for the
  // rest of the process; call it before declaring the parameters. Tests only.
  void register_test_shapes();

  void print_parameters(std::ostream &out, unsigned int dim, const std::string &style,
                        const std::vector<ParameterSection> &sections = {});
} // namespace mpm
