// Subsection Initial state of the parameter file: where the points come from (the prm's bodies
// or a saved FEM state, fem_state_file.h, and how that is placed), which MPM material each FEM
// material_id becomes, and the optional equilibration before t = 0.
#pragma once

#include <mpm/core/material/material.h>

#include <deal.II/base/parameter_handler.h>

#include <map>
#include <string>
#include <utility>
#include <vector>

namespace mpm
{
  struct InitialStateSettings
  {
    std::string  source   = "prm bodies";        // or "FEM file"
    std::string  fem_file;                       // Source = FEM file
    std::string  placement = "quadrature points"; // or "lattice"
    unsigned int points_per_direction = 2;       // Placement = lattice
    int          projection_degree    = -1;      // Placement = lattice; -1 = the FEM's degree
    // Damped steps at t = 0 until the points rest in the MPM's own equilibrium (Simulator)
    bool         equilibrate                 = false;
    double       equilibration_damping       = 0.8;
    double       equilibration_tolerance     = 1e-6; // largest point speed / sqrt(|g| H)
    unsigned int equilibration_maximum_steps = 100000;
    // FEM material_id -> (index into the materials, density): Materials, where given
    std::map<unsigned int, std::pair<unsigned int, double>> materials;

    // Declares the entries of subsection Initial state (prm inside it).
    static void declare(dealii::ParameterHandler &prm);
    // Reads them (prm inside subsection Initial state); Materials names one of material_names,
    // whose parameters (material_parameters) must have no random field. Throws naming the
    // entry on bad input.
    void parse(dealii::ParameterHandler &prm, const std::vector<std::string> &material_names,
               const std::vector<MaterialParameters<double>> &material_parameters);
  };
} // namespace mpm
