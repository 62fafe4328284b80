// Subsection Backend of the parameter file: where the MPM step runs (CPU or CUDA), in which
// precision, and the CUDA engine's own settings.
#pragma once

#include <deal.II/base/parameter_handler.h>

#include <string>

namespace mpm
{
  struct BackendSettings
  {
    std::string name             = "cpu"; // Backend/Backend: cpu | cuda
    int         sort_interval    = 20;    // cuda: steps between re-sorts of the points on the device
    bool        queue_steps      = true;  // cuda, one rank: steps queued before the last one ends
    bool        single_precision = false; // Precision = float: points, nodes and step in float

    // Declares the entries of subsection Backend (prm inside it).
    static void declare(dealii::ParameterHandler &prm);
    // Reads them (prm inside subsection Backend).
    void parse(dealii::ParameterHandler &prm);
  };
} // namespace mpm
