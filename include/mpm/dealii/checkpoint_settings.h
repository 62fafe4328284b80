// Subsection Checkpoint of the parameter file: when the run writes the checkpoints that
// --resume continues from (doc/checkpoints.md), where, and how many it keeps.
#pragma once

#include <deal.II/base/parameter_handler.h>

#include <string>

namespace mpm
{
  struct CheckpointSettings
  {
    unsigned int step_interval = 0;     // steps between checkpoints; 0 = none by steps
    double       wall_interval = 0;     // wall-clock minutes between checkpoints; 0 = none
    unsigned int keep          = 2;     // newest checkpoints kept
    std::string  directory;             // the checkpoints' folder (default: <Output/Directory>/checkpoints)
    bool         at_end        = false; // one more at the end of the run

    // Declares the entries of subsection Checkpoint (prm inside it).
    static void declare(dealii::ParameterHandler &prm);
    // Reads them (prm inside subsection Checkpoint); output_directory gives the default folder.
    void parse(dealii::ParameterHandler &prm, const std::string &output_directory);
  };
} // namespace mpm
