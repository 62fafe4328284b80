// The message of the stability check: the point that blew up and the remedies that fit.
#include "simulator_state.h"

namespace mpm
{
  namespace simulator_internal
  {
    // The message of engine_step's stability check: the point that blew up (the first whose
    // velocity, position, stress, deformation gradient or volume is not finite, else the
    // fastest; on several ranks the worst over the ranks, a collective call), what blew up,
    // and the remedies that fit the scene's settings.
    template <int dim>
    std::string describe_instability(Engine<dim> &engine, const Parameters &p, const double c_el, const double dt,
                                     const double reported_speed, const bool equilibrating, const bool parallel,
                                     MPI_Comm communicator)
    {
      const auto num = [](const double v) {
        std::ostringstream s;
        s.precision(4);
        s << v;
        return s.str();
      };
      PointSnapshot<dim> snapshot;
      engine.snapshot(snapshot);
      const HostPoints<dim, double> &x = snapshot.points;
      const auto finite = [](const double v) { return std::isfinite(v); };
      int         worst = -1, broken = -1;
      std::string quantity;
      double      fastest = -1;
      for (int i = 0; i < x.size() && broken < 0; ++i)
        {
          double v2 = 0;
          for (int d = 0; d < dim; ++d)
            v2 += x.velocity[d][i] * x.velocity[d][i];
          const auto all = [&](const auto &arrays, const int n) {
            for (int c = 0; c < n; ++c)
              if (!finite(arrays[c][i]))
                return false;
            return true;
          };
          quantity = !all(x.velocity, dim)                  ? "velocity" :
                     !all(x.position, dim)                  ? "position" :
                     !all(x.stress, n_voigt)                ? "stress" :
                     !all(x.deformation_gradient, dim * dim) ? "deformation gradient" :
                     !finite(x.volume[i])                   ? "volume" :
                                                              "";
          if (!quantity.empty())
            broken = worst = i;
          else if (std::sqrt(v2) > fastest)
            {
              fastest = std::sqrt(v2);
              worst   = i;
            }
        }

      const auto vector = [&](const auto &arrays, const int i) {
        std::string s = "(";
        for (int d = 0; d < dim; ++d)
          s += (d ? ", " : "") + num(arrays[d][i]);
        return s + ")";
      };
      std::string point = "no point";
      if (worst >= 0)
        {
          const int m = x.material[worst];
          point = "material point " + std::to_string(snapshot.labels->id[worst]) +
                  (m >= 0 ? " of material '" + p.material_names[m] + "' (" + p.material_models[m] + ")" :
                            std::string(", which left the grid in this step,")) +
                  " at " + vector(x.position, worst) + " (it started at " +
                  vector(snapshot.labels->initial_position, worst) + ")" +
                  (parallel ? " on MPI rank " + std::to_string(dealii::Utilities::MPI::this_mpi_process(communicator)) :
                              std::string()) +
                  ": " +
                  (broken >= 0 ? "its " + quantity + " is not a finite number (velocity " +
                                   vector(x.velocity, worst) + " m/s)" :
                                 "it moves at " + num(fastest) + " m/s, " + num(fastest / c_el) +
                                   " times the elastic wave speed " + num(c_el) + " m/s");
        }
      if (parallel)
        {
          // The worst over the ranks: a broken point first, then the fastest (the lowest rank on a tie).
          const double rank_score = broken >= 0 ? std::numeric_limits<double>::infinity() : fastest;
          const std::vector<double> scores = dealii::Utilities::MPI::all_gather(communicator, rank_score);
          const std::vector<std::string> points = dealii::Utilities::MPI::all_gather(communicator, point);
          const auto best = std::max_element(scores.begin(), scores.end()) - scores.begin();
          point           = points[best];
          broken          = scores[best] == std::numeric_limits<double>::infinity() ? 0 : -1;
          fastest         = scores[best];
        }
      // The fastest point may have left the grid in this step and be gone (on several ranks
      // the re-sort drops such points): say so before naming the fastest of those left.
      if (broken < 0 && std::isfinite(reported_speed) && fastest < 0.5 * reported_speed)
        point = "a point that left the grid in this step moved at " + num(reported_speed) + " m/s (" +
                num(reported_speed / c_el) + " times the elastic wave speed " + num(c_el) +
                " m/s); of the points left, the fastest is " + point;

      // What to change, as fits the scene.
      std::vector<std::string> advice;
      if (!(c_el > 0 && std::isfinite(c_el)))
        advice.push_back("the elastic wave speed c_el = " + num(c_el) +
                         " m/s that sets the time step is not a positive number: check the materials' Young's "
                         "modulus and Poisson's ratio and the bodies' Density");
      if (p.adaptive_time_step)
        advice.push_back("reduce Solver/CFL number (now " + num(p.cfl) + ")");
      else
        advice.push_back("reduce Solver/Fixed time step (now " + num(p.fixed_time_step) +
                         " s; the elastic limit h / c_el is " + num(p.cell_size / c_el) + " s, the last step " +
                         num(dt) + " s)");
      if (p.scheme == UpdateScheme::usl)
        advice.push_back("use Solver/Update scheme = MUSL (USL is the least stable where nodes carry little mass)");
      if (p.shape_function == ShapeFunction::linear)
        advice.push_back("use Solver/Shape function = GIMP (linear shape functions jump as points cross cells)");
      if (!equilibrating && !(p.damping > 0))
        advice.push_back("add Solver/Local damping (now 0; 0.05 to 0.1 calms a dynamic start)");
      if (p.flip_fraction >= 1)
        advice.push_back("blend in some PIC (Solver/FLIP fraction below 1, e.g. 0.99) against velocity noise");
      if (broken >= 0 && quantity != "velocity" && quantity != "position" && !parallel)
        advice.push_back("check the material's parameters: its " + quantity + " failed first");
      std::string remedies;
      for (std::size_t k = 0; k < advice.size(); ++k)
        remedies += (k == 0 ? "" : k + 1 == advice.size() ? "; or " : "; ") + advice[k];
      return point + ". " + (remedies.empty() ? std::string() : "To stabilise it: " + remedies + ".");
    }

    template std::string describe_instability<2>(Engine<2> &, const Parameters &, double, double, double, bool, bool,
                                                 MPI_Comm);
    template std::string describe_instability<3>(Engine<3> &, const Parameters &, double, double, double, bool, bool,
                                                 MPI_Comm);
  } // namespace simulator_internal
} // namespace mpm
