#include <mpm/dealii/strength_parameters.h>

#include <deal.II/base/exceptions.h>

#include <cmath>

namespace mpm
{
  using dealii::ExcMessage;
  namespace Patterns = dealii::Patterns;

  namespace
  {
    void require(const bool ok, const std::string &entry, const std::string &what)
    {
      AssertThrow(ok, ExcMessage("Entry '" + entry + "' " + what));
    }
    constexpr double degree = M_PI / 180.0;
  } // namespace

  void declare_elastic_parameters(dealii::ParameterHandler &prm)
  {
    prm.declare_entry("Young's modulus", "1e6", Patterns::Double(0), "Young's modulus E in Pa (> 0).");
    prm.declare_entry("Poisson's ratio", "0.3", Patterns::Double(-1, 0.5), "Poisson's ratio nu, -1 < nu < 0.5.");
  }

  LinearElasticParameters<double> parse_elastic_parameters(dealii::ParameterHandler &prm)
  {
    LinearElasticParameters<double> e;
    e.youngs_modulus = prm.get_double("Young's modulus");
    e.poissons_ratio = prm.get_double("Poisson's ratio");
    require(e.youngs_modulus > 0, "Young's modulus", "must be > 0, got " + prm.get("Young's modulus") + ".");
    require(e.poissons_ratio > -1 && e.poissons_ratio < 0.5, "Poisson's ratio",
            "must lie in (-1, 0.5), got " + prm.get("Poisson's ratio") + ".");
    return e;
  }

  void declare_strength_parameters(dealii::ParameterHandler &prm)
  {
    prm.declare_entry("Cohesion", "0", Patterns::Double(0), "Peak cohesion c (Pa).");
    prm.declare_entry("Friction angle", "30", Patterns::Double(0, 89), "Peak friction angle phi (degrees).");
    prm.declare_entry("Dilatancy angle", "0", Patterns::Double(0, 89),
                      "Dilatancy angle psi (degrees), 0 <= psi <= phi; psi = phi is associated flow.");
    prm.declare_entry("Residual cohesion", "0", Patterns::Double(0),
                      "Residual cohesion c_res (Pa) reached by linear softening, c_res <= c.");
    prm.declare_entry("Softening modulus", "0", Patterns::Double(0),
                      "H (Pa): c = max(c_res, c - H eps_p) with eps_p the accumulated equivalent plastic strain; "
                      "0 = no cohesion softening.");
    prm.declare_entry("Residual friction angle", "-1", Patterns::Double(-1, 89),
                      "Residual friction angle phi_res (degrees) for friction softening; -1 = no friction "
                      "softening (phi_res = phi).");
    prm.declare_entry("Friction softening strain", "0", Patterns::Double(0),
                      "Plastic strain at which phi reaches phi_res; 0 = the strain at which c reaches c_res.");
  }

  SofteningStrength<double> parse_strength_parameters(dealii::ParameterHandler &prm)
  {
    SofteningStrength<double> s;
    s.cohesion          = prm.get_double("Cohesion");
    s.friction_angle    = prm.get_double("Friction angle") * degree;
    s.dilatancy_angle   = prm.get_double("Dilatancy angle") * degree;
    s.residual_cohesion = prm.get_double("Residual cohesion");
    s.softening_modulus = prm.get_double("Softening modulus");
    const double phi_res = prm.get_double("Residual friction angle");
    s.residual_friction_angle   = phi_res < 0 ? s.friction_angle : phi_res * degree;
    s.friction_softening_strain = prm.get_double("Friction softening strain");
    require(s.dilatancy_angle <= s.friction_angle, "Dilatancy angle",
            "must not exceed the friction angle (" + prm.get("Friction angle") + "), got " +
              prm.get("Dilatancy angle") + ".");
    require(s.softening_modulus == 0 || s.residual_cohesion <= s.cohesion, "Residual cohesion",
            "must not exceed Cohesion (" + prm.get("Cohesion") + "), got " + prm.get("Residual cohesion") + ".");
    require(s.residual_friction_angle <= s.friction_angle, "Residual friction angle",
            "must not exceed the friction angle (" + prm.get("Friction angle") + ").");
    if (s.softening_modulus == 0)
      s.residual_cohesion = s.cohesion;
    return s;
  }
} // namespace mpm
