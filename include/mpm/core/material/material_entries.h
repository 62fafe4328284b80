// A built-in model's prm section, said without deal.II: the model declares its entries and
// reads them back through these two interfaces, and the deal.II layer (material_library.cc)
// implements them over a ParameterHandler. So a model is one core header (its traits, device
// functions and prm section) that the FEM stage, the CPU and the GPU share. Host only.
#pragma once

#include <mpm/core/material/linear_elastic.h>
#include <mpm/core/material/softening.h>

#include <cmath>
#include <limits>
#include <string>

namespace mpm
{
  // Where a model declares its entries (its subsection is already entered).
  class MaterialEntries
  {
  public:
    static constexpr double unbounded = std::numeric_limits<double>::max();

    virtual ~MaterialEntries() = default;
    // A real number in [min, max] (unbounded: no bound), its default as written in a prm file
    // and its documentation.
    virtual void real(const std::string &name, const std::string &default_value, double min, double max,
                      const std::string &documentation) = 0;
  };

  // Where a model reads them back.
  class MaterialEntryValues
  {
  public:
    virtual ~MaterialEntryValues() = default;
    virtual double      real(const std::string &name) const       = 0;
    virtual std::string as_written(const std::string &name) const = 0;
    // Refuses the value of entry `name`: the message reads "Entry 'name' what".
    [[noreturn]] virtual void fail(const std::string &name, const std::string &what) const = 0;

    void require(const bool ok, const std::string &name, const std::string &what) const
    {
      if (!ok)
        fail(name, what);
    }
  };

  // The elastic part every built-in model has.
  inline void declare_elastic_entries(MaterialEntries &entries)
  {
    entries.real("Young's modulus", "1e6", 0, MaterialEntries::unbounded, "Young's modulus E in Pa (> 0).");
    entries.real("Poisson's ratio", "0.3", -1, 0.5, "Poisson's ratio nu, -1 < nu < 0.5.");
  }

  inline LinearElasticParameters<double> parse_elastic_entries(const MaterialEntryValues &values)
  {
    LinearElasticParameters<double> e;
    e.youngs_modulus = values.real("Young's modulus");
    e.poissons_ratio = values.real("Poisson's ratio");
    values.require(e.youngs_modulus > 0, "Young's modulus",
                   "must be > 0, got " + values.as_written("Young's modulus") + ".");
    values.require(e.poissons_ratio > -1 && e.poissons_ratio < 0.5, "Poisson's ratio",
                   "must lie in (-1, 0.5), got " + values.as_written("Poisson's ratio") + ".");
    return e;
  }

  // Cohesion and friction with linear softening (softening.h), for the frictional models.
  inline void declare_strength_entries(MaterialEntries &entries)
  {
    const double none = MaterialEntries::unbounded;
    entries.real("Cohesion", "0", 0, none, "Peak cohesion c (Pa).");
    entries.real("Friction angle", "30", 0, 89, "Peak friction angle phi (degrees).");
    entries.real("Dilatancy angle", "0", 0, 89,
                 "Dilatancy angle psi (degrees), 0 <= psi <= phi; psi = phi is associated flow.");
    entries.real("Residual cohesion", "0", 0, none, "Residual cohesion c_res (Pa) reached by linear softening, c_res <= c.");
    entries.real("Softening modulus", "0", 0, none,
                 "H (Pa): c = max(c_res, c - H eps_p) with eps_p the accumulated equivalent plastic strain; "
                 "0 = no cohesion softening.");
    entries.real("Residual friction angle", "-1", -1, 89,
                 "Residual friction angle phi_res (degrees) for friction softening; -1 = no friction "
                 "softening (phi_res = phi).");
    entries.real("Friction softening strain", "0", 0, none,
                 "Plastic strain at which phi reaches phi_res; 0 = the strain at which c reaches c_res.");
  }

  inline SofteningStrength<double> parse_strength_entries(const MaterialEntryValues &values)
  {
    constexpr double          degree = M_PI / 180.0;
    SofteningStrength<double> s;
    s.cohesion           = values.real("Cohesion");
    s.friction_angle     = values.real("Friction angle") * degree;
    s.dilatancy_angle    = values.real("Dilatancy angle") * degree;
    s.residual_cohesion  = values.real("Residual cohesion");
    s.softening_modulus  = values.real("Softening modulus");
    const double phi_res = values.real("Residual friction angle");
    s.residual_friction_angle   = phi_res < 0 ? s.friction_angle : phi_res * degree;
    s.friction_softening_strain = values.real("Friction softening strain");
    values.require(s.dilatancy_angle <= s.friction_angle, "Dilatancy angle",
                   "must not exceed the friction angle (" + values.as_written("Friction angle") + "), got " +
                     values.as_written("Dilatancy angle") + ".");
    values.require(s.softening_modulus == 0 || s.residual_cohesion <= s.cohesion, "Residual cohesion",
                   "must not exceed Cohesion (" + values.as_written("Cohesion") + "), got " +
                     values.as_written("Residual cohesion") + ".");
    values.require(s.residual_friction_angle <= s.friction_angle, "Residual friction angle",
                   "must not exceed the friction angle (" + values.as_written("Friction angle") + ").");
    if (s.softening_modulus == 0)
      s.residual_cohesion = s.cohesion;
    return s;
  }
} // namespace mpm
