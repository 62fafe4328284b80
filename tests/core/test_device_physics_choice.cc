// Which of the step's two variants of device kernels a run needs (step.h's DevicePhysics): the
// standard kernels leave out Hencky's law, Mohr-Coulomb, U's domains and the affine transfers,
// so a run that asks for any of them must get the `all` kernels, and a standard step on an
// atomic backend (the device's paths) refuses U's domains instead of running uGIMP's.
// On the host both variants hold everything: the same step with the `all` variant on the
// serial atomic backend gives the CPU backend's domains. What the device's standard kernels leave
// out cannot be seen here (host code compiles it all); test_gpu_affine_hencky runs Mohr-Coulomb
// and U's domains on the GPU through the variant these functions pick.
#include "check.h"
#include "serial_atomic_backend.h"

#include <mpm/core/backend/cpu_backend.h>
#include <mpm/core/step.h>

#include "../../benchmarks/p1_scene.h"

#include <cmath>
#include <cstdio>
#include <vector>

using namespace mpm;
using namespace mpm_test;

int main()
{
  // Materials.
  {
    MaterialParameters<double> elastic, dp, mc, dp_hencky;
    elastic.model   = MaterialModel::linear_elastic;
    dp.model        = MaterialModel::drucker_prager;
    mc.model        = MaterialModel::mohr_coulomb;
    dp_hencky       = dp;
    dp_hencky.elastic_law = ElasticLaw::hencky;
    using Table = std::vector<MaterialParameters<double>>;
    check(!materials_need_all_physics(Table{elastic, dp}), "linear elastic and Drucker-Prager: standard kernels");
    check(materials_need_all_physics(Table{dp, mc}), "a Mohr-Coulomb material: the all kernels");
    check(materials_need_all_physics(Table{elastic, dp_hencky}), "a material with Hencky's law: the all kernels");
    check(!materials_need_all_physics(Table{}), "no material: standard kernels");
  }
  // Settings.
  {
    StepSettings<3, double> s;
    check(!settings_need_all_physics(s), "the defaults: standard kernels");
    for (const DomainUpdate d : {DomainUpdate::none, DomainUpdate::det_F, DomainUpdate::stretch})
      {
        s.domain_update = d;
        check(!settings_need_all_physics(s), "uGIMP, det F and F_ii domains: standard kernels");
      }
    s.domain_update = DomainUpdate::U;
    check(settings_need_all_physics(s), "U's domains: the all kernels");
    StepSettings<3, double> affine;
    affine.affine_state_variable = 0;
    check(settings_need_all_physics(affine), "an affine transfer: the all kernels");
  }
  // The step: U's domains refused by the standard variant on an atomic backend; the all variant
  // runs them and gives the CPU backend's domains.
  {
    HostGrid<3, double>                     grid;
    HostPoints<3, double>                   initial;
    std::vector<MaterialParameters<double>> materials;
    mpm_bench::make_p1(2, grid, initial, materials, false); // elastic, undamped, gravity at once:
    StepSettings<3, double> s = mpm_bench::p1_settings<double>(); // no switch that the order of a
    s.domain_update           = DomainUpdate::U;                  // sum can flip
    s.damping                 = 0;
    s.gravity[2]              = -9.81;
    const double dt           = 0.5 * mpm_bench::P1::h / mpm_bench::p1_wave_speed();
    SerialAtomicBackend     serial;
    HostPoints<3, double>   points = initial;
    check(throws_naming(
            [&] {
              explicit_step<3, GimpShape>(serial, grid.view(), points.view(), materials.data(), s, dt);
            },
            "GIMP's domains by U"),
          "U's domains in the standard kernels of an atomic backend");

    const int n_steps = 200;
    auto      run     = [&](auto &backend, HostPoints<3, double> &out, auto variant) {
      HostGrid<3, double> g = grid;
      out                   = initial;
      for (int k = 0; k < n_steps; ++k)
        explicit_step<3, GimpShape, decltype(variant)::value>(backend, g.view(), out.view(), materials.data(), s, dt);
    };
    CpuBackend            cpu;
    HostPoints<3, double> on_cpu, on_serial;
    run(cpu, on_cpu, std::integral_constant<DevicePhysics, DevicePhysics::standard>());
    run(serial, on_serial, std::integral_constant<DevicePhysics, DevicePhysics::all>());
    double largest = 0, change = 0;
    for (int d = 0; d < 3; ++d)
      for (int i = 0; i < initial.size(); ++i)
        {
          largest = std::max(largest, std::abs(on_cpu.domain_half_length[d][i] - on_serial.domain_half_length[d][i]));
          change  = std::max(change, std::abs(on_cpu.domain_half_length[d][i] - initial.domain_half_length[d][i]));
        }
    std::printf("U's domains after %d steps: the serial atomic backend's all kernels against the CPU backend "
                "%.2e m, the domains changed by up to %.2e m\n",
                n_steps, largest, change);
    check(change > 1e-9, "the domains changed over the steps (the update ran)");
    check_below(largest, 1e-12, "U's domains: the all variant on an atomic backend against the CPU backend");
  }
  return finish("test_device_physics_choice");
}
