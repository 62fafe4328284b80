// Subsection Output of the parameter file: where the run writes, how often, and what.
// Declared and parsed here (Parameters::output holds it); read by the output writer
// (output_writer.h) and the run's loop.
#pragma once

#include <deal.II/base/parameter_handler.h>

#include <string>
#include <vector>

namespace mpm
{
  struct OutputSettings
  {
    std::string              directory;
    double                   interval;             // simulated seconds between outputs; 0 = first and last only
    bool                     write_grid_fields;
    bool                     write_particles;
    unsigned int             history_every;        // steps between rows of history.csv
    double                   progress_interval;    // wall-clock seconds between progress lines; 0 = none
    bool                     write_particle_table;
    std::vector<std::string> particle_fields;      // those written to the .vtu (empty: all)
    std::string              compression;          // zlib level of the .vtu files: "best speed", ...
    bool                     in_background;        // compress and write files on a background thread
    unsigned int             files_per_rank;       // .vtu pieces per rank and output, written in parallel
    unsigned int             max_outputs = 10000;  // warn of more outputs than this; 0 = no warning

    // Declares the entries of subsection Output (prm inside it).
    static void declare(dealii::ParameterHandler &prm);
    // Reads them (prm inside subsection Output).
    void parse(dealii::ParameterHandler &prm);
  };
} // namespace mpm
