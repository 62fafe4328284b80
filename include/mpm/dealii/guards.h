// Guards of a run against input that would exhaust the machine, run for ever or be silently
// wrong (doc/guards.md). Each refusal throws naming the prm entry and what it allows; each
// warning is printed once (rank 0) to stderr and the run goes on.
//
// - the text of a parameter file, before deal.II reads it (check_parameter_file): a folder,
//   a file without a 'set' line, an include cycle are refused; a line continuation that
//   swallows the next statement and an entry set twice in one subsection are warned of;
// - the size of the run, from the parsed parameters (check_run_size, called by
//   Parameters::parse): grid indices that overflow their integer types and a first time step
//   that predicts more than Solver/Maximum predicted steps are refused; more outputs than
//   Output/Maximum number of outputs and a plasticity start after End time are warned of;
// - the memory, before anything is allocated (check_memory, called by the Simulator's
//   constructor): an estimate from the prm against the machine's available memory or
//   Resources/Memory limit.
#pragma once

#include <mpm/dealii/parameters.h>

#include <mpi.h>

#include <optional>
#include <set>
#include <string>

namespace mpm
{
  // "dealii-mpm: warning: Parameter 'entry': text" (entry empty: "dealii-mpm: warning: text")
  // on stderr, from rank 0 of MPI_COMM_WORLD only (every rank finds the same from the same prm).
  void warn_about_parameter(const std::string &entry, const std::string &text);

  // The text of the parameter file `filename` (and the files it includes), as deal.II's
  // ParameterHandler will read it: refuses a folder, a .prm file without any 'set' line
  // (empty, or comments only) and a file that includes itself directly or through others
  // (naming the file and line); warns of a line ending in a backslash (deal.II joins the next
  // line to it) where the next line is a statement of its own, and of an entry set twice in
  // one 'subsection ... end' block of one file (the last value wins; a subsection opened again
  // later, as overrides appended to a scene are, is not warned of). Returns the entries the
  // text sets, as paths "Section/Subsection/Entry" (none for .json or .xml files, which deal.II
  // reads whole: nullopt).
  std::optional<std::set<std::string>> check_parameter_file(const std::string &filename);
  // The same checks of prm text given as a string (no refusal of an empty text).
  std::set<std::string> check_parameter_text(const std::string &text);

  // Checks of what the text left out, which deal.II fills with defaults without a word. Refuses
  // (throws, naming the entry): a material of Materials/Names (where the text sets Names) without
  // any entry in its 'Material <name>' subsection; a body 1..Number of bodies (where the text sets
  // it) without any entry in its 'Body <i>' subsection; entries set in a registered model's
  // subsection of a material whose Model is another one (a model changed and its old parameters
  // left: the new model would run on its defaults). parameters: as parsed from that text;
  // set_entries: what check_parameter_file or check_parameter_text returned for it.
  void check_given_subsections(const Parameters &parameters, const std::set<std::string> &set_entries);

  // Checks of the parsed parameters that no pattern can express, all from the prm alone (so
  // that every rank finds the same): refuses grid and point counts beyond the 32-bit indices
  // of the grid, the engine and deal.II, and a first time step that predicts more steps than
  // Solver/Maximum predicted steps; warns of more outputs than Output/Maximum number of
  // outputs and of Solver/Plasticity start time after End time.
  void check_run_size(const Parameters &parameters);

  // The run's first time step as check_run_size predicts it: the elastic wave speed c_el of
  // the stiffest body (set_by names its entries; empty where no body or FEM material gives
  // one), the largest initial speed v0, dt (adaptive: CFL x h / (c_el + v0), else the fixed
  // step), and the steps to End time at that step (at most Maximum number of steps; landing:
  // an Output interval below dt sets them).
  struct FirstStep
  {
    double      c_el = 0, v0 = 0, dt = 0, steps = 0;
    bool        landing = false;
    std::string set_by;
  };
  FirstStep first_time_step(const Parameters &parameters);
  // Field outputs up to End time: one per Output interval, the initial state included, at most
  // one a step; with Output interval = 0 the initial and final states (one where End time = 0).
  double predicted_outputs(const Parameters &parameters);

  // What a run will allocate, estimated from the prm before it allocates anything.
  struct MemoryEstimate
  {
    double n_cells = 0, n_nodes = 0, n_points = 0, n_field_nodes = 0;
    double grid_bytes  = 0; // deal.II's grid, DoFs and vectors, the engine's nodes: shared by the ranks
    double point_bytes = 0; // the handler's and the engine's points, output copies: shared by the ranks
    double per_rank_bytes = 0; // on every rank: the generated bodies, the random fields, per_rank_grid_bytes
    double per_rank_grid_bytes = 0; // on every rank: the coarse grid and block tables (near the material, CPU ranks)
    double n_coarse_cells = 0, coarse_cell_edge = 0; // that coarse grid: its cells, their edge in lattice cells
    // The whole run on n ranks, and what one rank needs.
    double total(const unsigned int n_ranks) const { return grid_bytes + point_bytes + n_ranks * per_rank_bytes; }
    double of_one_rank(const unsigned int n_ranks) const
    {
      return (grid_bytes + point_bytes) / n_ranks + per_rank_bytes;
    }
  };
  // n_points < 0: the points of the prm's bodies, counted from their volumes and point spacing.
  // With Grid/Nodes = near material on one rank, or on several CPU ranks, the grid costs what
  // the cells near the material do, plus a few bytes per block of the box.
  MemoryEstimate estimate_memory(const Parameters &parameters, double n_points = -1, unsigned int n_ranks = 1);

  // Refuses, on every rank of `communicator` alike, a run whose estimate exceeds Resources/
  // Memory limit (where > 0) or the memory available on a node to the ranks it holds
  // (MemAvailable of /proc/meminfo), naming Grid/Cell size or the body that needs the most.
  void check_memory(const Parameters &parameters, MPI_Comm communicator);
} // namespace mpm
