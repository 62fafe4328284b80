// The affine transfers (TPIC, APIC), Hencky's law, Mohr-Coulomb and the material family's test member
// (J2 plasticity) on the GPU against the CPU,
// per point, FP64: the kernels of the step's DevicePhysics::all variant (step.h), which the
// device runs only where a run asks for them. Tolerances as in test_gpu_cpu_agreement.cu (its header says why):
// undamped elastic scenes 1e-10, Drucker-Prager and damped ones max(1e-10, 100x the CPU's own
// spread when its points are reordered). The affine matrices C_p are compared too, relative to
// the largest |C| of the CPU run. --short: the spinning blocks alone (the affine transfers'
// scatters), 30 steps each, for compute-sanitizer's racecheck (scripts/dev/gpu_tests_carried.sh).
#include "../core/check.h"
#include "../core/spinning_block.h"
#include "gpu_agreement.h"
#include "gpu_scenes.h"

#include <cmath>
#include <string>

using namespace mpm;
using namespace mpm_test;

// Largest difference of the affine matrices (state variables) between two runs, over the
// largest |C| of the first.
template <int dim>
double affine_difference(const HostPoints<dim, double> &ref, const HostPoints<dim, double> &other)
{
  if (other.n_state_variables() < dim * dim || ref.n_state_variables() < dim * dim)
    return INFINITY; // the device did not give the matrices back
  double scale = 0, diff = 0;
  for (int k = 0; k < dim * dim; ++k)
    for (int i = 0; i < ref.size(); ++i)
      {
        scale = std::max(scale, std::abs(ref.state_variables[k][i]));
        diff  = std::max(diff, std::abs(ref.state_variables[k][i] - other.state_variables[k][i]));
      }
  return diff / (scale > 0 ? scale : 1);
}

// The spinning block (tests/core/spinning_block.h), 300 steps (30 with --short), with an affine transfer.
static long spin_steps = 300;
template <int dim, typename Shape>
void spin_agreement(const char *method, const DomainUpdate update, const Transfer transfer)
{
  const long              n = spin_steps;
  HostPoints<dim, double> cpu, gpu, initial;
  spinning_block<dim, Shape, CpuTarget>(update, initial, M_PI / 2, 0, nullptr, transfer);
  const SpinResult on_cpu = spinning_block<dim, Shape, CpuTarget>(update, cpu, M_PI / 2, n, &initial, transfer);
  const std::string scene = std::string("spinning block ") + method + (dim == 2 ? " (2D)" : " (3D)");
  // The scene holds what the transfer promises, so that the agreement is about a working run.
  std::printf("%s: angular momentum kept %.6f on the CPU\n", scene.c_str(), on_cpu.momentum_ratio);
  check_below(std::abs(on_cpu.momentum_ratio - 1), 1e-3, (scene + ": the CPU keeps the angular momentum").c_str());
  for (const bool sorted : {false, true})
    {
      if (sorted)
        spinning_block<dim, Shape, CudaSortedTarget>(update, gpu, M_PI / 2, n, &initial, transfer);
      else
        spinning_block<dim, Shape, CudaTarget>(update, gpu, M_PI / 2, n, &initial, transfer);
      const std::string name = scene + (sorted ? ", GPU sorted every 7" : "");
      report<dim>(name.c_str(), compare_points(cpu, gpu, 0.125), Difference(), n, false);
      const double c = affine_difference(cpu, gpu);
      std::printf("%-34s affine matrices: GPU-CPU %.1e of max |C|\n", name.c_str(), c);
      check_below(c, tolerance, (name + ": affine matrices within 1e-10").c_str());
    }
}

int main(int argc, char **argv)
{
  int        usage_error = 0;
  const bool short_form  = short_form_option(argc, argv, "test_gpu_affine_hencky", &usage_error);
  if (usage_error != 0)
    return usage_error;
  if (!cuda_device_present("test_gpu_affine_hencky"))
    return skip_code;
  spin_steps = short_form ? 30 : 300;
  try
    {
      const AffineMatrix tpic = AffineMatrix::velocity_gradient, apic = AffineMatrix::b_d_inverse;
      // MUSL: the affine momentum in P2G and in the remap, C in the remap's gather.
      spin_agreement<2, GimpShape>("TPIC uGIMP", DomainUpdate::none, {0, true, tpic});
      spin_agreement<2, QuadraticBSplineShape>("APIC B-spline", DomainUpdate::none, {0, true, apic});
      // USL: C in grid_to_particle_velocity.
      spin_agreement<2, QuadraticBSplineShape>("APIC B-spline USL", DomainUpdate::none,
                                               {0, true, apic, UpdateScheme::usl});
      // 3D: cpGIMP U with TPIC; the cubic B-spline's 64 nodes with APIC.
      spin_agreement<3, GimpShape>("TPIC cpGIMP U", DomainUpdate::U, {0, true, tpic});
      spin_agreement<3, CubicBSplineShape>("APIC cubic B-spline", DomainUpdate::none, {0, true, apic});
      if (short_form)
        return finish("test_gpu_affine_hencky --short");
      {
        // V3 with Drucker-Prager and Hencky's law (2D: the closed-form principal stretches)
        const long            n      = 600;
        const ElasticLaw      hencky = ElasticLaw::hencky;
        HostPoints<2, double> cpu, gpu, initial;
        collapse<CpuTarget>(initial, 0, nullptr, true, false, hencky);
        collapse<CpuTarget>(cpu, n, &initial, true, false, hencky);
        const Difference spread = cpu_reordering_spread(initial, cpu, 0.005, [&](auto &out, const auto *start) {
          collapse<CpuTarget>(out, n, start, true, false, hencky);
        });
        const double yielded = plastic_fraction(cpu);
        std::printf("V3 Drucker-Prager, Hencky: %.1f%% of the points have yielded after %ld steps\n", 100 * yielded, n);
        check(yielded > 0.01, "V3 Hencky: the scene exercises the plastic return");
        // The law is in the run: Jaumann's stresses differ from Hencky's beyond the tolerance.
        HostPoints<2, double> jaumann;
        collapse<CpuTarget>(jaumann, n, &initial, true, false);
        const double law_difference = compare_points(cpu, jaumann, 0.005).stress;
        std::printf("V3 Drucker-Prager: Hencky against Jaumann, stress %.1e of max |sigma|\n", law_difference);
        check(law_difference > 1e3 * std::max(tolerance, 100 * spread.worst()),
              "V3: Hencky's stresses differ from Jaumann's by far more than the agreement's tolerance");
        collapse<CudaTarget>(gpu, n, &initial, true, false, hencky);
        report<2>("V3 collapse, DP, Hencky (2D)", compare_points(cpu, gpu, 0.005), spread, n, true);
        collapse<CudaSortedTarget>(gpu, n, &initial, true, false, hencky);
        report<2>("V3 collapse, DP, Hencky, GPU sorted every 7", compare_points(cpu, gpu, 0.005), spread, n, true);
      }
      {
        // V3 with Mohr-Coulomb (the strength of V3's Drucker-Prager): the all variant, picked by
        // materials_need_all_physics as DeviceEngine picks it.
        const long            n = 600;
        HostPoints<2, double> cpu, gpu, initial;
        collapse<CpuTarget>(initial, 0, nullptr, true);
        auto run = [&](auto &out, const auto *start) {
          collapse<CpuTarget>(out, n, start, true, false, ElasticLaw::jaumann_rate, false, false, 0,
                              MaterialModel::mohr_coulomb);
        };
        run(cpu, &initial);
        const Difference spread = cpu_reordering_spread(initial, cpu, 0.005, run);
        const double     yielded = plastic_fraction(cpu);
        std::printf("V3 Mohr-Coulomb: %.1f%% of the points have yielded after %ld steps\n", 100 * yielded, n);
        check(yielded > 0.01, "V3 Mohr-Coulomb: the scene exercises the plastic return");
        HostPoints<2, double> drucker_prager;
        collapse<CpuTarget>(drucker_prager, n, &initial, true);
        const double model_difference = compare_points(cpu, drucker_prager, 0.005).stress;
        std::printf("V3: Mohr-Coulomb against Drucker-Prager, stress %.1e of max |sigma|\n", model_difference);
        check(model_difference > 1e3 * std::max(tolerance, 100 * spread.worst()),
              "V3: Mohr-Coulomb's stresses differ from Drucker-Prager's by far more than the agreement's tolerance");
        collapse<CudaTarget>(gpu, n, &initial, true, false, ElasticLaw::jaumann_rate, false, false, 0,
                              MaterialModel::mohr_coulomb);
        report<2>("V3 collapse, Mohr-Coulomb (2D)", compare_points(cpu, gpu, 0.005), spread, n, true);
        collapse<CudaSortedTarget>(gpu, n, &initial, true, false, ElasticLaw::jaumann_rate, false, false, 0,
                              MaterialModel::mohr_coulomb);
        report<2>("V3 collapse, Mohr-Coulomb, GPU sorted every 7", compare_points(cpu, gpu, 0.005), spread, n, true);
      }
      {
        // V3 with the material family's test member (J2 plasticity, models/test_von_mises_model.h):
        // a model added by one file and one line runs on the device, in the all variant
        // (materials_need_all_physics, as DeviceEngine picks it).
        const long            n = 600;
        const auto            von_mises = MaterialModel::test_von_mises;
        HostPoints<2, double> cpu, gpu, initial;
        collapse<CpuTarget>(initial, 0, nullptr, true);
        auto run = [&](auto &out, const auto *start) {
          collapse<CpuTarget>(out, n, start, true, false, ElasticLaw::jaumann_rate, false, false, 0, von_mises);
        };
        run(cpu, &initial);
        const Difference spread  = cpu_reordering_spread(initial, cpu, 0.005, run);
        const double     yielded = plastic_fraction(cpu);
        std::printf("V3 test von Mises: %.1f%% of the points have yielded after %ld steps\n", 100 * yielded, n);
        check(yielded > 0.01, "V3 test von Mises: the scene exercises the plastic return");
        HostPoints<2, double> drucker_prager;
        collapse<CpuTarget>(drucker_prager, n, &initial, true);
        const double model_difference = compare_points(cpu, drucker_prager, 0.005).stress;
        check(model_difference > 1e3 * std::max(tolerance, 100 * spread.worst()),
              "V3: the test von Mises' stresses differ from Drucker-Prager's by far more than the tolerance");
        collapse<CudaTarget>(gpu, n, &initial, true, false, ElasticLaw::jaumann_rate, false, false, 0, von_mises);
        report<2>("V3 collapse, test von Mises (2D)", compare_points(cpu, gpu, 0.005), spread, n, true);
        collapse<CudaSortedTarget>(gpu, n, &initial, true, false, ElasticLaw::jaumann_rate, false, false, 0,
                                   von_mises);
        report<2>("V3 collapse, test von Mises, GPU sorted every 7", compare_points(cpu, gpu, 0.005), spread, n, true);
      }
      {
        // P1 with ep2-3De's Drucker-Prager and Hencky's law (3D: the eigen-decomposition), 2 cells
        // across, 200 steps, D = 0.1
        const long            n      = 200;
        const double          D      = mpm_bench::P1::damping;
        const auto            form   = LocalDampingForm::per_component;
        const ElasticLaw      hencky = ElasticLaw::hencky;
        HostPoints<3, double> cpu, gpu, initial;
        slump<CpuTarget>(2, initial, 0, static_cast<const HostPoints<3, double> *>(nullptr), D, true, form, 0, hencky);
        slump<CpuTarget>(2, cpu, n, &initial, D, true, form, 0, hencky);
        const Difference spread =
          cpu_reordering_spread(initial, cpu, mpm_bench::P1::h, [&](auto &out, const auto *start) {
            slump<CpuTarget>(2, out, n, start, D, true, form, 0, hencky);
          });
        std::printf("P1 Drucker-Prager, Hencky: %.1f%% of the points have yielded after %ld steps\n",
                    100 * plastic_fraction(cpu), n);
        slump<CudaSortedTarget>(2, gpu, n, &initial, D, true, form, 0, hencky);
        report<3>("P1/V5 slump, DP, Hencky, GPU sorted every 7", compare_points(cpu, gpu, mpm_bench::P1::h), spread,
                  n, true);
      }
    }
  catch (const std::exception &e)
    {
      std::printf("exception: %s\n", e.what());
      return 1;
    }
  return finish("test_gpu_affine_hencky");
}
