// Solver/Method = auto: the fastest method whose error, as the method study measured it on the
// study's scene of the same kind at the same resolution, is below a tolerance (doc/methods.md,
// "Choosing a method"). The study's rows are compiled in (source/dealii/method_study_table.inc, written
// by scripts/dev/method_table.py from doc/study.csv).
#pragma once

#include <mpm/core/domain_update.h>
#include <mpm/core/material/hencky.h>
#include <mpm/core/shape/shape_family.h>
#include <mpm/core/step/settings.h>

#include <string>
#include <vector>

namespace mpm
{
  // A method of the study: what it sets in the Solver section (and the elastic law).
  struct MethodSettings
  {
    std::string   name;  // the study's name (doc/study.csv)
    std::string   label; // for the log
    ShapeFunction shape;
    DomainUpdate  domain_update;
    bool          affine; // Velocity transfer = APIC or TPIC
    AffineMatrix  affine_matrix;
    double        flip_fraction; // the blend's (0 with an affine transfer)
    bool          hencky;
  };

  // The study's methods by name; throws std::out_of_range for another name.
  const MethodSettings &study_method(const std::string &name);

  // The scene kinds Method scene takes, each the study's scene it is read from.
  std::vector<std::string> method_scene_names();

  struct MethodChoice
  {
    MethodSettings method;
    double         expected_error = 0;
    double         relative_cost  = 0; // per point and step, against uGIMP with the blend on the same backend
    std::string    reason;             // for the log: the scene, the resolution, the pick and the ones passed over
  };

  // The cheapest method whose expected error at `cells` (cells across the bodies' largest extent)
  // is at most `tolerance`; cuda: costs measured on the GPU where the study has them. Methods with
  // Hencky's law only where hencky_allowed. Expected error: log-log interpolation between the study's
  // resolutions; beyond its finest, the finest's error; below its coarsest, the coarsest's scaled by
  // (coarsest / cells) (first order). A method unstable at a resolution next to `cells` is left out.
  // Costs within 10% count as equal (the study's timings are single runs), and the more accurate of
  // those wins. In 3D pure FLIP is left out (it broke down on P2, the 3D collapse; the study's scenes
  // are 2D). Throws std::invalid_argument, saying what the best method would give, where none reaches
  // the tolerance. CPDI and CPDI2q only where cpdi_allowed (one MPI rank, Grid/Nodes = all),
  // the cubic B-spline GIMP only where bspline3_gimp_allowed (one MPI rank; Grid/Nodes = all, or
  // near material on the CPU with blocks of at least 2 cells).
  MethodChoice choose_method(const std::string &scene, double cells, double tolerance, bool cuda,
                             bool hencky_allowed, unsigned int dim, bool cpdi_allowed = true,
                             bool bspline3_gimp_allowed = true);
} // namespace mpm
