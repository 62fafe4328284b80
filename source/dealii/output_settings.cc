#include <mpm/dealii/output_settings.h>

#include <deal.II/base/utilities.h>

namespace mpm
{
  using dealii::ParameterHandler;
  namespace Patterns = dealii::Patterns;

  void OutputSettings::declare(ParameterHandler &prm)
  {
    prm.declare_entry("Directory", "output", Patterns::DirectoryName(),
                      "Folder for .vtu/.pvtu/.pvd files and the time history; created if missing. Files of an earlier "
                      "run there that this run does not overwrite are kept, and the run warns of them at its end.");
    prm.declare_entry("Output interval", "0.1", Patterns::Double(0),
                      "Simulated time between field outputs (s); 0 = only the initial and final states.");
    prm.declare_entry("Write grid fields", "true", Patterns::Bool(),
                      "Write nodal mass and velocity of the background grid with each output.");
    prm.declare_entry("Write particles", "true", Patterns::Bool(),
                      "Write every material point with all its properties with each output.");
    prm.declare_entry("History every n steps", "10", Patterns::Integer(1),
                      "Steps between rows of the time history (history.csv).");
    prm.declare_entry("Progress interval", "2", Patterns::Double(0),
                      "Wall-clock seconds between progress lines on the screen; 0 = none.");
    prm.declare_entry("Write particle table", "false", Patterns::Bool(),
                      "Also write particle_table_NNNNN.R.csv (one per output and rank R): id, position and every "
                      "property in full precision, for comparisons the single-precision .vtu files cannot resolve.");
    prm.declare_entry("Particle fields", "all", Patterns::List(Patterns::Anything()),
                      "The point fields written to the particle .vtu files: all, or a comma-separated list of "
                      "mass, volume, initial_volume, velocity, stress, strain, F, domain_half_length, "
                      "initial_domain_half_length, plastic_strain, material_id, initial_position, material_field "
                      "and the state variables of the run's material models. The id and the position are always "
                      "written. A 3D point carries 39 values with all; fewer fields write smaller files faster. "
                      "The particle table (Write particle table) keeps every field.");
    prm.declare_entry("Compression", "best speed",
                      Patterns::Selection("best speed|default|best compression|no compression"),
                      "zlib compression level of the .vtu files (deal.II's VtkFlags::compression_level). best "
                      "speed: about as small as the others for MPM data, several times faster to write than "
                      "best compression (doc/performance.md, Output).");
    prm.declare_entry("Write in background", "true", Patterns::Bool(),
                      "Build, compress and write the output files on a background thread while the steps go on; "
                      "the points are copied first (one snapshot), so the steps cannot change what is written. With "
                      "Backend = cuda on Linux these threads run at a lower priority (nice 10), so that they do not "
                      "take the core of the thread that queues the steps. false: the run waits for each output to "
                      "be written.");
    prm.declare_entry("Files per rank", "1", Patterns::Integer(1, 256),
                      "Each rank writes its grid cells and its points as this many .vtu pieces per output (the "
                      ".pvtu record lists them all), built, compressed and written on as many threads: more than "
                      "1 speeds up the output of large scenes on many cores.");
    prm.declare_entry("Maximum number of outputs", "10000", Patterns::Integer(0),
                      "Warn (and run on) where Output interval and Solver/End time give more outputs than this "
                      "(each one .vtu files per rank and a .pvtu record for the grid and the points); 0 = no "
                      "warning.");
  }

  void OutputSettings::parse(ParameterHandler &prm)
  {
    directory  = prm.get("Directory");
    interval   = prm.get_double("Output interval");
    write_grid_fields = prm.get_bool("Write grid fields");
    write_particles   = prm.get_bool("Write particles");
    history_every     = prm.get_integer("History every n steps");
    progress_interval = prm.get_double("Progress interval");
    write_particle_table = prm.get_bool("Write particle table");
    particle_fields      = dealii::Utilities::split_string_list(prm.get("Particle fields"));
    if (particle_fields == std::vector<std::string>{"all"})
      particle_fields.clear();
    compression   = prm.get("Compression");
    in_background = prm.get_bool("Write in background");
    files_per_rank = prm.get_integer("Files per rank");
    max_outputs           = prm.get_integer("Maximum number of outputs");
  }
} // namespace mpm
