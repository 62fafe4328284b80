// A constitutive model written outside the library (a user's program, examples/custom_material):
// a class with a virtual stress update, called once per point and step. Built-in models are
// MPM_HOST_DEVICE functions selected by a tag so that the GPU needs no virtual calls; a user
// model runs on the CPU backend only (Backend = cuda refuses it by name).
#pragma once

#include <mpm/core/material/linear_elastic.h>
#include <mpm/core/small_tensor.h>

#include <string>
#include <vector>

namespace mpm
{
  // A state variable of a model besides stress and plastic strain (a void ratio, a hardening
  // parameter, a damage variable): its name in output and in the FEM hand-over, and its
  // value at the start of a run for the points of the prm's bodies.
  struct StateVariable
  {
    std::string name;
    double      initial_value = 0;
  };

  class UserConstitutiveModel
  {
  public:
    virtual ~UserConstitutiveModel() = default;

    // The model's own state variables, in the order update_stress() receives them (at most
    // max_state_variables, config.h). Every point carries them from the start of the run
    // (the handler, output, migration between MPI ranks, the FEM hand-over); none by default.
    virtual std::vector<StateVariable> state_variables() const { return {}; }

    // The stress update of one point over one step (updated Lagrangian, as the built-in models):
    //   d_eps    strain increment, sym(L) dt, Voigt order xx yy zz xy yz xz, tensor shears;
    //   d_spin   spin increment, skew(L) dt (rotate_jaumann(stress, d_spin) is the Jaumann part);
    //   plastic  false before Solver/Plasticity start time: behave elastically, keep eps_p;
    //   stress   Cauchy stress (Pa, tension positive), updated in place;
    //   plastic_strain  the accumulated equivalent plastic strain, updated in place;
    //   state_variables the point's values of state_variables(), in that order, updated in
    //                   place (null when the model declares none).
    // Called concurrently for different points: it must not change the model's own members.
    virtual void update_stress(const SymTensor<double> &d_eps, const Mat3<double> &d_spin, bool plastic,
                               SymTensor<double> &stress, double &plastic_strain,
                               double *state_variables) const = 0;

    // The elastic constants the time step and the wave speed come from (the stiffest
    // response the model can give).
    virtual LinearElasticParameters<double> elastic_parameters() const = 0;
  };
} // namespace mpm
