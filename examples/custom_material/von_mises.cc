// von_mises.cc: a constitutive model of the user's own, in one file, registered by name.
//
// Undrained clay in a total stress analysis is commonly modelled as perfectly plastic with
// the undrained shear strength s_u as its only strength parameter (phi = 0). The von Mises
// surface sqrt(J2) = s_u matches Tresca's tau_max = s_u in plane strain, where the
// out-of-plane stress is the mean of the in-plane ones at yield; this is the model here.
//
// What dealii-mpm asks of a model written outside the library (mpm/core/material/user_model.h):
//   - a class derived from mpm::UserConstitutiveModel with the stress update of one point over
//     one step, and the elastic constants the time step is computed from;
//   - static declare_parameters(prm) and parse_parameters(prm), for the model's own subsection of
//     the parameter file ("subsection von mises" inside "subsection Material <name>");
//   - one line, MPM_REGISTER_CONSTITUTIVE_MODEL, that gives it a name: from then on a prm file
//     selects it with "set Model = von mises", as it selects the built-in models.
#include <mpm/core/material/objective_rotation.h>
#include <mpm/dealii/material_library.h>

#include <deal.II/base/exceptions.h>
#include <deal.II/base/parameter_handler.h>

#include <cmath>

namespace
{
  class VonMises : public mpm::UserConstitutiveModel
  {
  public:
    // The entries of "subsection von mises", each with a pattern and a documentation string,
    // as dealii-mpm --print-parameters shows them for the built-in models.
    static void declare_parameters(dealii::ParameterHandler &prm)
    {
      prm.declare_entry("Young's modulus", "1e6", dealii::Patterns::Double(0), "Young's modulus E in Pa (> 0).");
      prm.declare_entry("Poisson's ratio", "0.3", dealii::Patterns::Double(-1, 0.5),
                        "Poisson's ratio nu, -1 < nu < 0.5.");
      prm.declare_entry("Undrained shear strength", "1e4", dealii::Patterns::Double(0),
                        "s_u in Pa (> 0): the surface sqrt(J2) = s_u.");
    }

    // Reads them (the subsection is entered). Values the patterns let through but the model
    // cannot use are refused here, naming the entry; the run stops before it starts.
    void parse_parameters(dealii::ParameterHandler &prm)
    {
      elastic.youngs_modulus = prm.get_double("Young's modulus");
      elastic.poissons_ratio = prm.get_double("Poisson's ratio");
      shear_strength         = prm.get_double("Undrained shear strength");
      AssertThrow(elastic.youngs_modulus > 0, dealii::ExcMessage("Entry 'Young's modulus' must be > 0."));
      AssertThrow(elastic.poissons_ratio < 0.5, dealii::ExcMessage("Entry 'Poisson's ratio' must be < 0.5."));
      AssertThrow(shear_strength > 0, dealii::ExcMessage("Entry 'Undrained shear strength' must be > 0."));
    }

    mpm::LinearElasticParameters<double> elastic_parameters() const override
    {
      return elastic;
    }

    // One step of one point: Jaumann rotation of the old stress and an elastic trial (the
    // library's own helpers), then, once plasticity is on, the radial return of the deviator
    // to the surface. The plastic strain counts the equivalent plastic strain
    // sqrt(2/3 de_p : de_p) of the return.
    void update_stress(const mpm::SymTensor<double> &d_eps, const mpm::Mat3<double> &d_spin, const bool plastic,
                       mpm::SymTensor<double> &stress, double &plastic_strain, double *) const override
    {
      const mpm::SymTensor<double> rotated = mpm::rotate_jaumann(stress, d_spin);
      const mpm::SymTensor<double> d_sigma = mpm::elastic_stress_increment(elastic, d_eps);
      for (int i = 0; i < 6; ++i)
        stress[i] = rotated[i] + d_sigma[i];
      if (!plastic)
        return;

      // Voigt order xx yy zz xy yz xz; the shear entries count twice in s : s.
      const double pressure = (stress[0] + stress[1] + stress[2]) / 3;
      double       s[6], s_norm2 = 0;
      for (int i = 0; i < 6; ++i)
        {
          s[i] = stress[i] - (i < 3 ? pressure : 0.0);
          s_norm2 += (i < 3 ? 1.0 : 2.0) * s[i] * s[i];
        }
      const double sqrt_J2 = std::sqrt(0.5 * s_norm2);
      if (sqrt_J2 <= shear_strength)
        return;
      const double scale = shear_strength / sqrt_J2;
      for (int i = 0; i < 6; ++i)
        stress[i] = (i < 3 ? pressure : 0.0) + scale * s[i];
      // |s_trial| - |s| = 2 G |de_p|
      const double G = elastic.shear_modulus();
      plastic_strain += std::sqrt(2.0 / 3.0) * std::sqrt(2.0) * (sqrt_J2 - shear_strength) / (2 * G);
    }

  private:
    mpm::LinearElasticParameters<double> elastic{};
    double                               shear_strength = 0;
  };
} // namespace

MPM_REGISTER_CONSTITUTIVE_MODEL(VonMises, "von mises",
                                "von Mises (J2) perfect plasticity with the undrained shear strength s_u.");
