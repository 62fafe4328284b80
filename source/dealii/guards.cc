// Guards of a run against bad input (doc/guards.md): what include/mpm/dealii/guards.h says.
#include <mpm/dealii/guards.h>
#include <mpm/dealii/material_library.h>

#include <deal.II/base/exceptions.h>
#include <deal.II/base/mpi.h>
#include <deal.II/base/utilities.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <limits>
#include <map>
#include <sstream>
#include <vector>

namespace mpm
{
  using dealii::ExcMessage;

  namespace
  {
    std::string number(const double x)
    {
      std::ostringstream s;
      s.precision(4);
      s << x;
      return s.str();
    }

    [[noreturn]] void refuse(const std::string &entry, const std::string &what)
    {
      AssertThrow(false, ExcMessage("Parameter '" + entry + "': " + what));
      throw; // not reached
    }

    // ---- The text of a parameter file, read as deal.II's ParameterHandler::parse_input
    // reads it (9.4): each line trimmed; a line ending in '\' joined with the next; then a
    // comment from '#' removed, tabs made spaces, and the line trimmed again; statements
    // 'subsection NAME', 'end', 'set NAME = VALUE', 'include FILE' (also upper case). An
    // included file is opened by its name as written (relative to the working directory)
    // and read inside the current subsection.

    bool starts_with(const std::string &line, const std::string &word)
    {
      std::string upper = word;
      std::transform(upper.begin(), upper.end(), upper.begin(), ::toupper);
      return line.compare(0, word.size(), word) == 0 || line.compare(0, upper.size(), upper) == 0;
    }

    // A line as scan_line sees it: no comment, no tabs, trimmed.
    std::string statement_of(std::string line)
    {
      if (line.find('#') != std::string::npos)
        line.erase(line.find('#'));
      std::replace(line.begin(), line.end(), '\t', ' ');
      return dealii::Utilities::trim(line);
    }

    bool is_statement(const std::string &line)
    {
      const std::string s = statement_of(line);
      return starts_with(s, "set ") || starts_with(s, "subsection ") || starts_with(s, "include ") || s == "end" ||
             s == "END";
    }

    struct TextScan
    {
      std::vector<std::string> including; // the files being read, outermost first (canonical)
      std::vector<std::string> shown;     // the same as the user wrote them
      bool                     any_set = false;
      std::set<std::string>    set_entries; // every entry set, as its path "Section/Entry"
    };

    void scan_text(std::istream &input, const std::string &name, std::vector<std::string> path, TextScan &scan)
    {
      // (entry path, subsection block) -> (line, value) of its last 'set' in this file. A block
      // is one 'subsection ... end' (0: the top level): a subsection opened again later, as
      // overrides appended to a scene are, may set an entry again without a warning.
      std::map<std::pair<std::string, unsigned int>, std::pair<unsigned int, std::string>> set_at;
      std::vector<unsigned int> blocks;
      unsigned int              n_blocks = 0;
      std::vector<std::string> lines;
      for (std::string line; std::getline(input, line);)
        lines.push_back(dealii::Utilities::trim(line));

      std::string joined;
      unsigned int first_line = 0; // where the logical line starts (1-based)
      for (unsigned int n = 0; n < lines.size(); ++n)
        {
          const std::string &line = lines[n];
          if (joined.empty() && first_line == 0)
            first_line = n + 1;
          const bool continued = !line.empty() && line.back() == '\\';
          if (continued)
            {
              // deal.II joins the next line to this one, whatever it holds: a statement on
              // the next line is then lost in this line's value (or comment).
              const bool at_end = n + 1 == lines.size();
              if (at_end || is_statement(lines[n + 1]))
                {
                  const std::string s = statement_of(joined + line.substr(0, line.size() - 1));
                  std::string       entry;
                  if (starts_with(s, "set ") && s.find('=') != std::string::npos)
                    {
                      entry = dealii::Utilities::trim(s.substr(4, s.find('=') - 4));
                      for (auto p = path.rbegin(); p != path.rend(); ++p)
                        entry = *p + "/" + entry;
                    }
                  warn_about_parameter(entry, "line " + std::to_string(n + 1) + " of the parameter file '" + name +
                                         "' ends in a backslash, which continues it on the next line" +
                                         (at_end ? " (there is none)" :
                                                   ": line " + std::to_string(n + 2) + " ('" + lines[n + 1] +
                                                     "') becomes part of " +
                                                     (entry.empty() ? "this line" : "this entry's value") +
                                                     " and is not read as a statement of its own") +
                                         ". Remove the backslash unless the value really goes on.");
                }
              joined += line.substr(0, line.size() - 1);
              if (!at_end)
                continue;
            }
          else
            joined += line;
          const unsigned int where = first_line;
          const std::string  s     = statement_of(joined);
          joined.clear();
          first_line = 0;

          if (starts_with(s, "subsection "))
            {
              path.push_back(dealii::Utilities::trim(s.substr(11)));
              blocks.push_back(++n_blocks);
            }
          else if (starts_with(s, "end"))
            {
              if (!path.empty())
                path.pop_back();
              if (!blocks.empty())
                blocks.pop_back();
            }
          else if (starts_with(s, "set ") && s.find('=') != std::string::npos)
            {
              scan.any_set            = true;
              std::string       entry = dealii::Utilities::trim(s.substr(4, s.find('=') - 4));
              const std::string value = dealii::Utilities::trim(s.substr(s.find('=') + 1));
              for (auto p = path.rbegin(); p != path.rend(); ++p)
                entry = *p + "/" + entry;
              scan.set_entries.insert(entry);
              const auto key    = std::make_pair(entry, blocks.empty() ? 0u : blocks.back());
              const auto before = set_at.find(key);
              if (before != set_at.end())
                warn_about_parameter(entry, "set twice in one subsection of '" + name + "', in line " +
                                              std::to_string(before->second.first) + " (" + before->second.second +
                                              ") and in line " + std::to_string(where) + " (" + value +
                                              "); the last value is used. Remove one of them.");
              set_at[key] = {where, value};
            }
          else if (starts_with(s, "include "))
            {
              const std::string file = dealii::Utilities::trim(s.substr(8));
              std::ifstream     included(file);
              if (file.empty() || !included)
                continue; // deal.II's own message names the line
              // A folder reads as empty, /dev/zero or /dev/urandom never end: only a file is read.
              AssertThrow(std::filesystem::is_regular_file(file),
                          ExcMessage("The parameter file '" + name + "', line " + std::to_string(where) +
                                     ": 'include " + file + "' names " +
                                     (std::filesystem::is_directory(file) ? "a folder" : "a device or pipe") +
                                     ", not a file. Include a parameter file (.prm) by its path."));
              std::error_code   error;
              const std::string canonical = std::filesystem::weakly_canonical(file, error).string();
              const auto        cycle     = std::find(scan.including.begin(), scan.including.end(), canonical);
              if (cycle != scan.including.end())
                {
                  std::string chain;
                  for (auto f = scan.shown.begin() + (cycle - scan.including.begin()); f != scan.shown.end(); ++f)
                    chain += "'" + *f + "' includes ";
                  AssertThrow(false, ExcMessage("The parameter file '" + name + "', line " + std::to_string(where) +
                                                ": 'include " + file + "' closes an include cycle (" + chain +
                                                "'" + file + "' again), which would be read without end. A "
                                                "parameter file may include others, but none may include itself, "
                                                "directly or through another file: remove this line."));
                }
              scan.including.push_back(canonical);
              scan.shown.push_back(file);
              scan_text(included, file, path, scan);
              scan.including.pop_back();
              scan.shown.pop_back();
            }
        }
    }

    // ---- The size of a run.

    constexpr double max_index = std::numeric_limits<int>::max(); // 2^31 - 1

    // Points of a body: its volume times (points per cell direction / h)^dim.
    double points_of_body(const BodyParameters &body, const Parameters &p)
    {
      const unsigned int dim = p.dim;
      double             volume = 1;
      if (body.shape == "polygon")
        {
          double area = 0;
          for (std::size_t i = 0, j = body.polygon.size() - 1; i < body.polygon.size(); j = i++)
            area += body.polygon[j][0] * body.polygon[i][1] - body.polygon[i][0] * body.polygon[j][1];
          volume = 0.5 * std::abs(area) * (dim == 3 ? body.upper[1] - body.lower[1] : 1.0);
        }
      else if (body.shape == "cylinder")
        volume = std::min(M_PI * body.radius * body.radius,
                          (body.upper[0] - body.lower[0]) * (body.upper[1] - body.lower[1])) *
                 (body.upper[2] - body.lower[2]);
      else
        for (unsigned int d = 0; d < dim; ++d)
          volume *= body.upper[d] - body.lower[d];
      return volume * std::pow(body.points_per_direction / p.cell_size, dim);
    }

    // Bytes per item of a run, from the maximum resident set size of runs of 20 steps with
    // the t = 0 and final outputs on one rank (Debian 12's deal.II 9.4, doc/guards.md): 2D
    // 1.05e6 cells and 6.6e4 points 1.63 GB, 6.6e4 cells and 1.05e6 points 1.79 GB; 3D
    // 2.1e6 cells and 3.3e4 points 4.37 GB, 3.3e4 cells and 2.1e6 points 4.42 GB; nothing
    // 0.17 GB. That is 1330 (2D) and 2010 (3D) bytes per grid cell (deal.II's Triangulation
    // with its coarser levels, DoFHandler, Partitioner and vectors, the grid's output, the
    // engine's lattice nodes and cell sums) and 1500 (2D) and 2040 (3D) bytes per point (the
    // ParticleHandler's properties, the engine's arrays, the output's snapshot, and the
    // bodies' points as generated, which every rank holds whole: HostPoints' 236 and 308
    // bytes a point and the ordering). Rounded up by about 5%.
    struct BytesPer
    {
      double cell, point, generated_point, program;
    };
    BytesPer bytes_per(const unsigned int dim)
    {
      return dim == 2 ? BytesPer{1400, 1250, 330, 0.17e9} : BytesPer{2100, 1700, 430, 0.17e9};
    }
  } // namespace

  void warn_about_parameter(const std::string &entry, const std::string &text)
  {
    int initialized = 0, finalized = 0;
    MPI_Initialized(&initialized);
    MPI_Finalized(&finalized);
    if (initialized && !finalized && dealii::Utilities::MPI::this_mpi_process(MPI_COMM_WORLD) != 0)
      return;
    std::cerr << "dealii-mpm: warning: " << (entry.empty() ? "" : "Parameter '" + entry + "': ") << text << std::endl;
  }

  std::optional<std::set<std::string>> check_parameter_file(const std::string &filename)
  {
    AssertThrow(!std::filesystem::is_directory(filename),
                ExcMessage("The parameter file '" + filename + "' is a folder, not a file. Give the scene's "
                           "parameter file: dealii-mpm scene.prm (a .prm file; dealii-mpm --print-parameters 2 "
                           "prints every entry with its default)."));
    AssertThrow(!std::filesystem::exists(filename) || std::filesystem::is_regular_file(filename),
                ExcMessage("The parameter file '" + filename + "' is a device or pipe, not a file. Give the "
                           "scene's parameter file: dealii-mpm scene.prm."));
    const std::string ending = filename.substr(filename.find_last_of('.') + 1);
    if (ending != "prm" && ending != "PRM")
      return std::nullopt; // .xml, .json: deal.II reads them whole; other endings it refuses itself
    std::ifstream in(filename);
    TextScan      scan;
    std::error_code error;
    scan.including.push_back(std::filesystem::weakly_canonical(filename, error).string());
    scan.shown.push_back(filename);
    scan_text(in, filename, {}, scan);
    AssertThrow(scan.any_set,
                ExcMessage("The parameter file '" + filename + "' has no 'set' line: it is empty or holds only "
                           "comments, and would run the default scene. Give the scene's entries as 'set NAME = "
                           "VALUE' lines in their subsections (dealii-mpm --print-parameters 2 prints every entry "
                           "with its default)."));
    return scan.set_entries;
  }

  std::set<std::string> check_parameter_text(const std::string &text)
  {
    std::istringstream in(text);
    TextScan           scan;
    scan_text(in, "input string", {}, scan);
    return scan.set_entries;
  }

  void check_given_subsections(const Parameters &p, const std::set<std::string> &set_entries)
  {
    // The entries set under a subsection path (prefix ending in '/').
    const auto entries_under = [&set_entries](const std::string &prefix) {
      std::vector<std::string> found;
      for (auto e = set_entries.lower_bound(prefix); e != set_entries.end() && e->compare(0, prefix.size(), prefix) == 0;
           ++e)
        found.push_back(e->substr(prefix.size()));
      return found;
    };
    for (std::size_t m = 0; m < p.material_names.size(); ++m)
      {
        const std::string section = "Material " + p.material_names[m];
        // The default material ('soil', linear elastic, when Names is not set) is a documented default.
        AssertThrow(set_entries.count("Materials/Names") == 0 || !entries_under(section + "/").empty(),
                    ExcMessage("Parameter 'Materials/Names': the material '" + p.material_names[m] +
                               "' has no entry in the parameter file: no 'subsection " + section +
                               "' sets anything, so its Model (linear elastic by default) and all its parameters "
                               "would be defaults. Give it a 'subsection " + section + "' with 'set Model = ...' "
                               "and the model's parameters, or remove the name from Materials/Names."));
        for (const auto &library_entry : material_library())
          {
            const std::string &model = library_entry.first;
            if (model == p.material_models[m])
              continue;
            const std::vector<std::string> unread = entries_under(section + "/" + model + "/");
            if (unread.empty())
              continue;
            std::string list;
            for (const std::string &e : unread)
              list += (list.empty() ? "" : ", ") + e;
            AssertThrow(false, ExcMessage("Parameter '" + section + "/Model': it is '" + p.material_models[m] +
                                          "', but the parameter file sets entries of the model '" + model +
                                          "' (" + list + " in 'subsection " + model +
                                          "'), which this material would not read: the run would use '" +
                                          p.material_models[m] + "' with its own entries. Set Model = " + model +
                                          ", or remove 'subsection " + model + "' from 'subsection " + section +
                                          "'."));
          }
      }
    // The same for the default body (one, a 1 m box) where Number of bodies is not set.
    for (std::size_t b = 1; b <= p.bodies.size(); ++b)
      AssertThrow(set_entries.count("Material points/Number of bodies") == 0 ||
                    !entries_under("Material points/Body " + std::to_string(b) + "/").empty(),
                  ExcMessage("Parameter 'Material points/Number of bodies': it is " +
                             std::to_string(p.bodies.size()) + ", but the parameter file sets nothing in 'subsection "
                             "Body " + std::to_string(b) + "' of 'Material points', so that body would be the "
                             "default one (a 1 m box at the origin). Give every body 1.." +
                             std::to_string(p.bodies.size()) + " its subsection, or set Number of bodies to the "
                             "bodies you describe."));
  }

  MemoryEstimate estimate_memory(const Parameters &p, double n_points, const unsigned int n_ranks)
  {
    const unsigned int dim = p.dim;
    MemoryEstimate     e;
    e.n_cells = e.n_nodes = 1;
    for (unsigned int d = 0; d < dim; ++d)
      {
        const double n = std::round((p.upper[d] - p.lower[d]) / p.cell_size);
        e.n_cells *= n;
        e.n_nodes *= n + 1;
      }
    if (n_points < 0)
      {
        n_points = 0;
        for (const BodyParameters &body : p.bodies)
          n_points += points_of_body(body, p);
      }
    e.n_points = n_points;

    // The random fields, built on every rank while the points are generated: an FFT lattice
    // over the grid plus 6 correlation lengths (24 bytes a node), its values (8 bytes), as in
    // GaussianRandomField.
    double field_bytes = 0;
    for (unsigned int m = 0; m < p.materials.size(); ++m)
      if (p.materials[m].field_parameter != FieldParameter::none)
        {
          const RandomFieldParameters &rf      = p.material_fields[m];
          double                       spacing = p.cell_size, embedded = 1, lattice = 1;
          for (unsigned int d = 0; d < dim; ++d)
            spacing = std::min(spacing, rf.correlation_length[d] / 4);
          for (unsigned int d = 0; d < dim; ++d)
            {
              const double n = std::ceil((p.upper[d] - p.lower[d]) / spacing) + 1;
              lattice *= n;
              embedded *= n + std::ceil(6 * rf.correlation_length[d] / spacing) + 1;
            }
          e.n_field_nodes += embedded;
          field_bytes += 24 * embedded + 8 * lattice;
        }

    const BytesPer b = bytes_per(dim);
    e.grid_bytes     = b.cell * e.n_cells;
    // Nodes near the material on one rank: no deal.II grid of the box; the chooser's mark
    // and table entry per block (5 bytes per B^dim cells) and the kept nodes, about four
    // times the cells the bodies fill (the material spreads, and a block's neighbours are
    // kept) at the engine's nodal arrays, cell sums, numbering and grid output (500 bytes).
    double material_cells = 0;
    for (const BodyParameters &body : p.bodies)
      material_cells += points_of_body(body, p) / std::pow(body.points_per_direction, dim);
    const double n_blocks = e.n_cells / std::pow(p.active_block_cells, dim);
    double      &per_rank_grid_bytes = e.per_rank_grid_bytes;
    if (p.active_block_cells > 0 && n_ranks == 1)
      e.grid_bytes = 5 * n_blocks + 500 * std::min(e.n_cells, 4 * material_cells);
    // Near the material on several ranks (CPU): deal.II's grid fine only near the material (a
    // cell's bytes for about four times the cells the bodies fill, as above), and on every rank
    // the coarse grid (cells of 2^L x k lattice cells, BackgroundGrid) and the blocks' marks and
    // table (about 6 bytes a block); the lookups span only a rank's own cells.
    else if (p.active_block_cells > 0 && p.backend.name == "cpu")
      {
        unsigned int levels = 10;
        for (unsigned int d = 0; d < dim; ++d)
          {
            const long   cells_of_k = std::lround((p.upper[d] - p.lower[d]) / p.cell_size) / p.cells_per_grid_cell;
            unsigned int twos       = 0;
            while (twos < levels && cells_of_k > 0 && (cells_of_k >> twos) % 2 == 0)
              ++twos;
            levels = std::min(levels, twos);
          }
        e.coarse_cell_edge = double(p.cells_per_grid_cell << levels);
        e.n_coarse_cells   = e.n_cells / std::pow(e.coarse_cell_edge, dim);
        e.grid_bytes       = b.cell * std::min(e.n_cells, 4 * material_cells);
        per_rank_grid_bytes = 6 * n_blocks + b.cell * e.n_coarse_cells;
      }
    e.point_bytes    = b.point * e.n_points;
    e.per_rank_bytes = b.program + b.generated_point * e.n_points + field_bytes + per_rank_grid_bytes;
    return e;
  }

  FirstStep first_time_step(const Parameters &p)
  {
    // The elastic wave speed of the stiffest body sets the first step (the adaptive step
    // shrinks further as the points speed up).
    FirstStep f;
    auto      wave_speed = [&](const unsigned int material, const double density, const std::string &where) {
      const double c = std::sqrt(p.materials[material].elastic.p_wave_modulus() / density);
      if (!(c <= f.c_el)) // the largest, or the first that is not a number
        {
          f.c_el   = c;
          f.set_by = "Material " + p.material_names[material] + "/" + p.material_models[material] +
                     "/Young's modulus (" + number(p.materials[material].elastic.youngs_modulus) +
                     " Pa) and Poisson's ratio (" + number(p.materials[material].elastic.poissons_ratio) + ") with " +
                     where + " (" + number(density) + " kg/m^3)";
        }
    };
    for (unsigned int b = 0; b < p.bodies.size(); ++b)
      {
        wave_speed(p.body_material[b], p.bodies[b].density, "Material points/Body " + std::to_string(b + 1) + "/Density");
        double v2 = 0;
        for (const double v : p.bodies[b].velocity)
          v2 += v * v;
        f.v0 = std::max(f.v0, std::sqrt(v2));
      }
    for (const auto &[id, material_and_density] : p.initial_state.materials)
      wave_speed(material_and_density.first, material_and_density.second,
                 "the density of Initial state/Materials' id " + std::to_string(id));
    if (f.set_by.empty())
      return f;
    f.dt    = p.adaptive_time_step ? p.cfl * p.cell_size / (f.c_el + f.v0) : p.fixed_time_step;
    f.steps = p.end_time / f.dt;
    // An output interval below the step cuts every step to land on an output time (at
    // least 1e-12 End time, source/dealii/simulator.cc): the outputs then set the steps.
    f.landing = p.output.interval > 0 && p.output.interval < f.dt;
    if (f.landing)
      f.steps = p.end_time / std::max(p.output.interval, 1e-12 * p.end_time);
    if (p.max_steps > 0)
      f.steps = std::min(f.steps, double(p.max_steps));
    return f;
  }

  double predicted_outputs(const Parameters &p)
  {
    if (!(p.output.interval > 0))
      return p.end_time > 0 ? 2 : 1; // the initial and the final state
    double outputs = std::floor(p.end_time / p.output.interval * (1 + 1e-12)) + 1;
    if (p.max_steps > 0)
      outputs = std::min(outputs, p.max_steps + 1.0); // at most one a step
    return outputs;
  }

  void check_run_size(const Parameters &p)
  {
    const unsigned int dim = p.dim;

    // The grid: lattice indices are int (the engine's nodes and points, HostGrid), deal.II's
    // cell, DoF and particle indices 32-bit unsigned.
    std::string  cells;
    unsigned int most_points_per_direction = p.initial_state.points_per_direction;
    for (const BodyParameters &body : p.bodies)
      most_points_per_direction = std::max(most_points_per_direction, body.points_per_direction);
    for (unsigned int d = 0; d < dim; ++d)
      cells += (d ? " x " : "") + number(std::round((p.upper[d] - p.lower[d]) / p.cell_size));
    const MemoryEstimate e = estimate_memory(p);
    for (unsigned int d = 0; d < dim; ++d)
      if (std::round((p.upper[d] - p.lower[d]) / p.cell_size) * most_points_per_direction > max_index ||
          !(e.n_nodes <= max_index))
        refuse("Grid/Cell size", number(p.cell_size) + " m divides the grid into " + cells + " cells (" +
                                   number(e.n_cells) + " cells, " + number(e.n_nodes) +
                                   " nodes), more than the 2147483647 nodes (and point sites along an axis) that "
                                   "the grid's and the engine's 32-bit indices can number. Is the cell size "
                                   "mistyped? A cell size must give at most 2147483647 nodes, and a run that fits "
                                   "in the memory (doc/guards.md).");
    if (!(e.n_points <= max_index))
      {
        unsigned int largest = 0;
        for (unsigned int b = 1; b < p.bodies.size(); ++b)
          if (points_of_body(p.bodies[b], p) > points_of_body(p.bodies[largest], p))
            largest = b;
        refuse("Material points/Body " + std::to_string(largest + 1) + "/Points per cell direction",
               "the bodies hold about " + number(e.n_points) + " material points (" +
                 std::to_string(p.bodies[largest].points_per_direction) + " per cell direction on cells of " +
                 number(p.cell_size) + " m), more than the 2147483647 that the engine's 32-bit indices can "
                 "number. Check Grid/Cell size and Points per cell direction.");
      }

    const FirstStep first  = first_time_step(p);
    const double    c_el   = first.c_el, v0 = first.v0;
    const auto     &set_by = first.set_by;
    if (!set_by.empty() && p.max_predicted_steps > 0)
      {
        const double dt = first.dt, steps = first.steps;
        const bool   landing = first.landing;
        if (landing && !(steps <= p.max_predicted_steps))
          refuse("Output/Output interval",
                 number(p.output.interval) + " s is below the first time step " + number(dt) +
                   " s, and every step is cut to land on an output time: about " + number(steps) +
                   " steps to Solver/End time = " + number(p.end_time) + " s, more than Solver/Maximum "
                   "predicted steps = " + number(p.max_predicted_steps) + ": the run would not end. Is the "
                   "interval mistyped? 0 writes only the initial and final states.");
        if (!(steps <= p.max_predicted_steps))
          refuse("Solver/Maximum predicted steps",
                 "the first time step " +
                   (p.adaptive_time_step ?
                      "dt = CFL number x Cell size / (c_el + |v|) = " + number(p.cfl) + " x " + number(p.cell_size) +
                        " m / (" + number(c_el) + " + " + number(v0) + ") m/s = " + number(dt) + " s" :
                      "(Solver/Fixed time step) = " + number(dt) + " s") +
                   " predicts " + number(steps) + " steps to Solver/End time = " + number(p.end_time) +
                   " s, more than Solver/Maximum predicted steps = " + number(p.max_predicted_steps) +
                   ": the run would not end. The elastic wave speed c_el = sqrt((K + 4G/3) / rho) = " +
                   number(c_el) + " m/s comes from " + set_by +
                   ". Check these entries, Grid/Cell size, Solver/CFL number and Solver/End time for a mistyped "
                   "exponent; to run that long, raise Solver/Maximum predicted steps (0 = no limit) or set "
                   "Solver/Maximum number of steps.");
      }

    // Warnings: the run goes on.
    if (p.output.interval > 0 && p.output.max_outputs > 0 && (p.output.write_grid_fields || p.output.write_particles))
      {
        const double outputs = predicted_outputs(p);
        if (outputs > p.output.max_outputs)
          warn_about_parameter("Output/Output interval",
                               number(p.output.interval) + " s up to Solver/End time = " + number(p.end_time) +
                                 " s writes " + number(outputs) + " outputs (each .vtu files of the grid and the "
                                 "points on every rank, and a .pvtu record), more than Output/Maximum number of "
                                 "outputs = " + std::to_string(p.output.max_outputs) + ". Raise the interval, or the "
                                 "maximum if you mean it (0 = no warning).");
      }
    // With pure FLIP, what a fixed node passes back is its old velocity, the mean of its points': the
    // change moves FLIP's noise between the points beside the boundary instead of removing it.
    bool fixed_faces = false;
    for (unsigned int id = 0; id < 2 * dim; ++id)
      fixed_faces |= p.boundary[id] == BoundaryType::no_slip || p.boundary[id] == BoundaryType::free_slip;
    // Disconnected points (a material's Disconnection volume ratio) took the burst away.
    const bool disconnects = std::any_of(p.materials.begin(), p.materials.end(), [](const auto &m) {
      return m.disconnection_volume_ratio > 0;
    });
    if (p.flip_fixed_velocity_change && p.flip_fraction >= 1 && !p.apic && fixed_faces && !disconnects)
      warn_about_parameter("Solver/FLIP at fixed nodes",
                           "velocity change with Solver/FLIP fraction = 1 (pure FLIP): one run in four of the 2D "
                           "granular collapse at 2.5 mm burst (doc/methods.md, \"FLIP at a no-slip base\"). Blend "
                           "in some PIC (FLIP fraction 0.99-0.995), or let dilated points disconnect (Material X/"
                           "Disconnection volume ratio, e.g. 2); with either it was stable in every run measured.");
    if (p.plasticity_start_time > p.end_time)
      for (unsigned int m = 0; m < p.materials.size(); ++m)
        if (built_in_model_is(p.materials[m].model, [](auto member) { return decltype(member)::plastic; }, true))
          {
            warn_about_parameter("Solver/Plasticity start time",
                                 number(p.plasticity_start_time) + " s is after Solver/End time = " +
                                   number(p.end_time) + " s: material '" + p.material_names[m] + "' (" +
                                   p.material_models[m] + ") and every other plastic model stays elastic for the "
                                   "whole run.");
            break;
          }
  }

  void check_memory(const Parameters &p, MPI_Comm communicator)
  {
    const unsigned int   n_ranks = dealii::Utilities::MPI::n_mpi_processes(communicator);
    const MemoryEstimate e       = estimate_memory(p, -1, n_ranks);
    const double         GB      = 1e9;

    // What limits: Resources/Memory limit for the whole run, else each node's available
    // memory shared by the ranks it holds (the least of the nodes, alike on every rank).
    double      need = e.total(n_ranks), available = p.memory_limit * GB;
    std::string against = "Resources/Memory limit";
    if (!(p.memory_limit > 0))
      {
        double        bytes = -1;
        std::ifstream meminfo("/proc/meminfo");
        for (std::string key; meminfo >> key;)
          {
            double kB = 0;
            meminfo >> kB;
            meminfo.ignore(std::numeric_limits<std::streamsize>::max(), '\n');
            if (key == "MemAvailable:")
              bytes = kB * 1024;
          }
        int      ranks_here = 1;
        MPI_Comm node;
        if (n_ranks > 1 && MPI_Comm_split_type(communicator, MPI_COMM_TYPE_SHARED, 0, MPI_INFO_NULL, &node) ==
                             MPI_SUCCESS)
          {
            MPI_Comm_size(node, &ranks_here);
            MPI_Comm_free(&node);
          }
        // Per rank; a machine whose memory cannot be read does not limit.
        const double per_rank = bytes > 0 ? bytes / ranks_here : std::numeric_limits<double>::max();
        available             = n_ranks > 1 ? dealii::Utilities::MPI::min(per_rank, communicator) : per_rank;
        need                  = e.of_one_rank(n_ranks);
        against = n_ranks > 1 ? "the memory available to each rank (MemAvailable of /proc/meminfo on its node, "
                                "shared by the node's ranks)" :
                                "the memory available (MemAvailable of /proc/meminfo)";
      }
    if (need <= available)
      return;

    // Name what needs the most: the grid, a body's points, or a random field.
    const double fields = e.per_rank_bytes - bytes_per(p.dim).generated_point * e.n_points - bytes_per(p.dim).program -
                          e.per_rank_grid_bytes;
    const double grid   = e.grid_bytes + n_ranks * e.per_rank_grid_bytes;
    std::string  entry  = "Grid/Cell size";
    // Near the material on several ranks: deal.II's coarse grid, on every rank, can be the most.
    const bool coarse_grid = n_ranks * e.per_rank_grid_bytes > std::max(e.grid_bytes, e.point_bytes) &&
                             e.per_rank_grid_bytes > fields;
    if (coarse_grid)
      entry = "Grid/Cells per deal.II cell";
    else if (e.point_bytes > grid && e.point_bytes > fields && !p.bodies.empty())
      {
        unsigned int largest = 0;
        for (unsigned int b = 1; b < p.bodies.size(); ++b)
          if (points_of_body(p.bodies[b], p) > points_of_body(p.bodies[largest], p))
            largest = b;
        entry = "Material points/Body " + std::to_string(largest + 1) + "/Points per cell direction";
      }
    else if (fields > grid && fields > e.point_bytes)
      for (unsigned int m = 0; m < p.materials.size(); ++m)
        if (p.materials[m].field_parameter != FieldParameter::none)
          entry = "Material " + p.material_names[m] + "/Random field/Correlation lengths";
    std::string parts = number(e.n_cells) + " grid cells of " + number(p.cell_size) + " m (" +
                        number(grid / GB) + " GB), " + number(e.n_points) + " material points (" +
                        number((e.point_bytes + (e.per_rank_bytes - fields - bytes_per(p.dim).program -
                                                 e.per_rank_grid_bytes) * n_ranks) / GB) +
                        " GB)";
    if (e.n_field_nodes > 0)
      parts += ", random fields of " + number(e.n_field_nodes) + " nodes (" + number(fields / GB) + " GB on each rank)";
    if (coarse_grid)
      parts += "; of the grid, deal.II's coarse grid on each rank: " + number(e.n_coarse_cells) + " cells of " +
               number(e.coarse_cell_edge) + " lattice cells along each axis (Cells per deal.II cell = " +
               std::to_string(p.cells_per_grid_cell) + " times the largest power of two, at most 1024, that "
               "divides every count of deal.II cells), " + number(e.per_rank_grid_bytes / GB) + " GB";
    const std::string advice =
      coarse_grid ? "Raise Grid/Cells per deal.II cell (it must divide the cells along every direction), or choose "
                    "the extent and Grid/Cell size so that the cell counts hold powers of two; more ranks do not "
                    "help, every rank holds the coarse grid." :
                    "Check Grid/Cell size (a mistyped exponent?) and Points per cell direction, or run on more nodes.";
    refuse(entry, "the run would need about " + number(need / GB) + " GB" +
                    (n_ranks > 1 && !(p.memory_limit > 0) ? " per rank" : "") + ", more than the " +
                    number(available / GB) + " GB of " + against + ". Estimated from the prm (doc/guards.md): " +
                    parts + ", on " + std::to_string(n_ranks) + " rank(s). " + advice + " Resources/Memory limit "
                    "(GB, > 0) replaces the machine's available memory as the limit.");
  }
} // namespace mpm
