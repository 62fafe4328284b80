#include <mpm/dealii/method_choice.h>

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <map>
#include <sstream>
#include <stdexcept>

namespace mpm
{
  namespace
  {
    struct StudyRow
    {
      const char *scene;
      const char *method;
      double      cells;
      double      error;     // -1: unstable
      double      cost_cpu;  // per point-step over uGIMP's, CPU
      double      cost_cuda; // the same on the GPU; -1: not measured there
    };

    const StudyRow study_rows[] = {
#include "method_study_table.inc"
    };

    // The methods of scripts/validation/study.py (METHODS), with what each sets.
    const std::vector<MethodSettings> &methods()
    {
      const auto g = ShapeFunction::gimp, b2 = ShapeFunction::bspline2, b3 = ShapeFunction::bspline3,
                 lin = ShapeFunction::linear, cpdi = ShapeFunction::cpdi, cpdi2q = ShapeFunction::cpdi2q,
                 b3_gimp = ShapeFunction::bspline3_gimp;
      const auto none = DomainUpdate::none, det_f = DomainUpdate::det_F, f_ii = DomainUpdate::stretch,
                 u = DomainUpdate::U;
      const auto tpic = AffineMatrix::velocity_gradient, apic = AffineMatrix::b_d_inverse;
      static const std::vector<MethodSettings> all = {
        {"gimp", "uGIMP, FLIP 0.99", g, none, false, tpic, 0.99, false},
        {"linear", "linear, FLIP 0.99", lin, none, false, tpic, 0.99, false},
        {"cpgimp_det_f", "cpGIMP det F, FLIP 0.99", g, det_f, false, tpic, 0.99, false},
        {"cpgimp_f_ii", "cpGIMP F_ii, FLIP 0.99", g, f_ii, false, tpic, 0.99, false},
        {"cpgimp_u", "cpGIMP U, FLIP 0.99", g, u, false, tpic, 0.99, false},
        {"bspline2", "quadratic B-spline, FLIP 0.99", b2, none, false, tpic, 0.99, false},
        {"bspline3", "cubic B-spline, FLIP 0.99", b3, none, false, tpic, 0.99, false},
        {"gimp_pic", "uGIMP, PIC", g, none, false, tpic, 0, false},
        {"gimp_flip", "uGIMP, pure FLIP", g, none, false, tpic, 1, false},
        {"bspline2_pic", "quadratic B-spline, PIC", b2, none, false, tpic, 0, false},
        {"gimp_tpic", "uGIMP, TPIC", g, none, true, tpic, 0, false},
        {"bspline2_tpic", "quadratic B-spline, TPIC", b2, none, true, tpic, 0, false},
        {"bspline2_apic", "quadratic B-spline, APIC", b2, none, true, apic, 0, false},
        {"cpgimp_u_hencky", "cpGIMP U, FLIP 0.99, Hencky", g, u, false, tpic, 0.99, true},
        {"cpdi", "CPDI, FLIP 0.99", cpdi, none, false, tpic, 0.99, false},
        {"cpdi2q", "CPDI2q, FLIP 0.99", cpdi2q, none, false, tpic, 0.99, false},
        {"bspline3_gimp_f_ii", "cubic B-spline GIMP F_ii, FLIP 0.99", b3_gimp, f_ii, false, tpic, 0.99, false},
      };
      return all;
    }

    struct Estimate
    {
      bool        known = false; // false: left out, `why` says why
      double      error = 0;
      std::string why;
    };

    std::string cells_text(const double cells)
    {
      std::ostringstream s;
      s << std::setprecision(3) << cells;
      return s.str();
    }

    // The method's expected error at `cells` from its rows (sorted by cells).
    Estimate estimate(const std::vector<const StudyRow *> &rows, const double cells)
    {
      Estimate e;
      const StudyRow *below = nullptr, *above = nullptr;
      for (const StudyRow *r : rows)
        {
          if (r->cells <= cells)
            below = r;
          if (r->cells >= cells && above == nullptr)
            above = r;
        }
      // A method that broke down on the study's scene at any resolution is left out: where it breaks
      // depends on more than the resolution (run length, how far the material moves).
      for (const StudyRow *r : rows)
        if (r->error < 0)
          {
            e.why = "unstable in the study at " + cells_text(r->cells) + " cells";
            return e;
          }
      e.known = true;
      if (below != nullptr && above != nullptr && above->cells == below->cells)
        {
          e.error = below->error;
          e.why   = "at the study's " + cells_text(below->cells) + " cells";
        }
      else if (below != nullptr && above != nullptr)
        {
          const double t = std::log(cells / below->cells) / std::log(above->cells / below->cells);
          e.error         = std::exp((1 - t) * std::log(below->error) + t * std::log(above->error));
          e.why = "between the study's " + cells_text(below->cells) + " and " + cells_text(above->cells) + " cells";
        }
      else if (below != nullptr)
        {
          e.error = below->error;
          e.why   = "the study's finest, " + cells_text(below->cells) + " cells";
        }
      else
        {
          e.error = above->error * above->cells / cells;
          e.why   = "below the study's coarsest (" + cells_text(above->cells) + " cells), scaled at first order";
        }
      return e;
    }
  } // namespace

  const MethodSettings &study_method(const std::string &name)
  {
    for (const MethodSettings &m : methods())
      if (m.name == name)
        return m;
    throw std::out_of_range("study_method: no method '" + name + "'");
  }

  std::vector<std::string> method_scene_names()
  {
    std::vector<std::string> names;
    for (const StudyRow &r : study_rows)
      if (std::find(names.begin(), names.end(), r.scene) == names.end())
        names.emplace_back(r.scene);
    return names;
  }

  MethodChoice choose_method(const std::string &scene, const double cells, const double tolerance, const bool cuda,
                             const bool hencky_allowed, const unsigned int dim, const bool cpdi_allowed,
                             const bool bspline3_gimp_allowed)
  {
    if (!(cells > 0) || !(tolerance > 0))
      throw std::invalid_argument("choose_method: cells and tolerance must be > 0");
    std::map<std::string, std::vector<const StudyRow *>> by_method;
    for (const StudyRow &r : study_rows)
      if (scene == r.scene)
        by_method[r.method].push_back(&r);
    if (by_method.empty())
      throw std::invalid_argument("choose_method: the study has no scene '" + scene + "'");

    struct Candidate
    {
      const MethodSettings *method;
      double                error, cost;
      bool                  cost_from_cpu;
      std::string           why;
    };
    std::vector<Candidate> candidates;
    std::ostringstream     left_out;
    for (auto &[name, rows] : by_method)
      {
        std::sort(rows.begin(), rows.end(), [](const StudyRow *a, const StudyRow *b) { return a->cells < b->cells; });
        const MethodSettings &m = study_method(name);
        if (m.hencky && !hencky_allowed)
          {
            left_out << "\n    " << m.label << ": Hencky needs built-in models only";
            continue;
          }
        if ((m.shape == ShapeFunction::cpdi || m.shape == ShapeFunction::cpdi2q) && !cpdi_allowed)
          {
            left_out << "\n    " << m.label << ": runs on one MPI rank with Grid/Nodes = all";
            continue;
          }
        if (m.shape == ShapeFunction::bspline3_gimp && !bspline3_gimp_allowed)
          {
            left_out << "\n    " << m.label << ": runs on one MPI rank, with Grid/Nodes = all, or near material "
                     << "on the CPU with Active block size >= 2";
            continue;
          }
        if (dim == 3 && m.shape == ShapeFunction::cpdi2q)
          {
            left_out << "\n    " << m.label << ": two-dimensional";
            continue;
          }
        if (dim == 3 && !m.affine && m.flip_fraction == 1)
          {
            left_out << "\n    " << m.label << ": unstable on P2, the 3D collapse (doc/methods.md)";
            continue;
          }
        const Estimate e = estimate(rows, cells);
        if (!e.known)
          {
            left_out << "\n    " << m.label << ": " << e.why;
            continue;
          }
        const bool cpu_cost = !cuda || rows.front()->cost_cuda < 0;
        candidates.push_back({&m, e.error, cpu_cost ? rows.front()->cost_cpu : rows.front()->cost_cuda,
                              cuda && cpu_cost, e.why});
      }
    // By cost, then error: the first within the tolerance is the pick.
    std::sort(candidates.begin(), candidates.end(), [](const Candidate &a, const Candidate &b) {
      return a.cost != b.cost ? a.cost < b.cost : a.error < b.error;
    });
    auto describe = [&](const Candidate &c) {
      std::ostringstream s;
      s << c.method->label << ": expected error " << std::setprecision(2) << c.error << " (" << c.why << "), cost "
        << std::setprecision(3) << c.cost << "x uGIMP's" << (c.cost_from_cpu ? " (the CPU's; not measured on the GPU)" : "");
      return s.str();
    };
    std::ostringstream header;
    header << "Method = auto: scene kind '" << scene << "', " << cells_text(cells)
           << " cells across the bodies' largest extent, tolerance " << tolerance << ", " << (cuda ? "cuda" : "cpu")
           << " costs";
    // Costs within 10% of the cheapest within the tolerance count as equal (the study's timings are
    // single runs on a shared machine): of those, the most accurate.
    const Candidate *cheapest = nullptr, *pick = nullptr, *best = nullptr;
    for (const Candidate &c : candidates)
      {
        if (cheapest == nullptr && c.error <= tolerance)
          cheapest = &c;
        if (best == nullptr || c.error < best->error)
          best = &c;
      }
    for (const Candidate &c : candidates)
      if (cheapest != nullptr && c.error <= tolerance && c.cost <= 1.1 * cheapest->cost &&
          (pick == nullptr || c.error < pick->error))
        pick = &c;
    if (pick == nullptr)
      {
        std::ostringstream s;
        s << header.str() << ": no method of the study is expected within the tolerance at this resolution; the most "
          << "accurate is " << (best != nullptr ? describe(*best) : std::string("none")) << ".";
        throw std::invalid_argument(s.str());
      }
    MethodChoice choice;
    choice.method         = *pick->method;
    choice.expected_error = pick->error;
    choice.relative_cost  = pick->cost;
    std::ostringstream s;
    s << header.str() << ".\n  picked " << describe(*pick)
      << ";\n  as cheap (within 10%) or cheaper, passed over (less accurate, or above the tolerance):";
    bool any = false;
    for (const Candidate &c : candidates)
      if (&c != pick && c.cost <= 1.1 * pick->cost)
        {
          s << "\n    " << describe(c);
          any = true;
        }
    if (!any)
      s << " none";
    const std::string out = left_out.str();
    if (!out.empty())
      s << "\n  left out:" << out;
    choice.reason = s.str();
    return choice;
  }
} // namespace mpm
