// A per-point field added by one line (point_fields.h: test_tag, owned by `test`, so no run
// allocates it unless asked) follows its points everywhere the points go: the engine's sorts,
// the re-sorts and migration between ranks (2 ranks), a checkpoint and the run resumed from it,
// and the particle table. Each point's tag is set once to a function of its initial position;
// after the steps every point in the table must still hold that value. A run that does not
// ask for the field carries no array for it and writes no column.
#include "../core/check.h"

#include <mpm/core/point_fields.h>
#include <mpm/dealii/parameters.h>
#include <mpm/dealii/simulator.h>

#include <deal.II/base/mpi.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <vector>

using namespace mpm;

namespace
{
  // A small granular collapse: the points move across cells (and ranks) within a few steps.
  std::string scene(const std::string &directory, const int steps)
  {
    return R"(
set Dimension = 2
subsection Grid
  set Lower corner = 0, 0
  set Upper corner = 0.4, 0.12
  set Cell size    = 0.01
end
subsection Boundary conditions
  set y min = no-slip
  set y max = free
end
subsection Solver
  set End time = 1
  set Maximum number of steps = )" +
           std::to_string(steps) + R"(
  set Gravity = 0, -9.81
  set CFL number = 0.5
end
subsection Backend
  set Sort interval = 3
end
subsection Parallel
  set Re-sort distance = 0.1
end
subsection Materials
  set Names = sand
end
subsection Material sand
  set Model = drucker prager
  subsection drucker prager
    set Young's modulus = 1e6
    set Poisson's ratio = 0.3
    set Friction angle  = 20
  end
end
subsection Material points
  set Number of bodies = 1
  subsection Body 1
    set Lower corner = 0, 0
    set Upper corner = 0.2, 0.1
    set Density      = 2650
    set Material     = sand
    set Initial velocity = 2, 0
  end
end
subsection Output
  set Directory            = )" +
           directory + R"(
  set Output interval      = 0
  set Write particle table = true
  set Write grid fields    = false
end
subsection Checkpoint
  set Directory = )" +
           directory + R"(/checkpoints
end
)";
  }

  // A check that says what it checked on rank 0, and fails on any rank.
  void expect(const bool ok, const std::string &what)
  {
    if (ok && dealii::Utilities::MPI::this_mpi_process(MPI_COMM_WORLD) == 0)
      std::printf("ok: %s\n", what.c_str());
    mpm_test::check(ok, what.c_str());
  }

  // The tag a point starts with: its initial position, encoded.
  double tag_of(const double x, const double y) { return 1000 * x + y; }

  // The rows of every particle table of the last output, as column -> values.
  std::map<std::string, std::vector<double>> last_tables(const std::string &directory)
  {
    std::map<std::string, std::vector<double>> columns;
    std::string                                newest;
    for (const auto &entry : std::filesystem::directory_iterator(directory))
      {
        const std::string name = entry.path().filename();
        if (name.rfind("particle_table_", 0) == 0 && name.substr(0, 20) > newest.substr(0, 20))
          newest = name;
      }
    for (const auto &entry : std::filesystem::directory_iterator(directory))
      {
        const std::string name = entry.path().filename();
        if (newest.empty() || name.substr(0, 20) != newest.substr(0, 20))
          continue;
        std::ifstream            in(entry.path());
        std::string              line, cell;
        std::vector<std::string> header;
        std::getline(in, line);
        for (std::istringstream row(line); std::getline(row, cell, ',');)
          header.push_back(cell);
        while (std::getline(in, line))
          {
            std::istringstream row(line);
            for (const std::string &column : header)
              {
                std::getline(row, cell, ',');
                columns[column].push_back(std::stod(cell));
              }
          }
      }
    return columns;
  }

  // Whether every point of the tables holds the tag of its initial position (and how many).
  bool tags_follow_points(const std::map<std::string, std::vector<double>> &t, int &n)
  {
    n = 0;
    if (t.count("test_tag") == 0 || t.count("initial_position_x") == 0)
      return false;
    const auto &tag = t.at("test_tag"), &x = t.at("initial_position_x"), &y = t.at("initial_position_y");
    for (std::size_t i = 0; i < tag.size(); ++i, ++n)
      if (tag[i] != tag_of(x[i], y[i]))
        return false;
    return n > 0;
  }
} // namespace

int main(int argc, char **argv)
{
  dealii::Utilities::MPI::MPI_InitFinalize mpi(argc, argv, 1);
  try
  {
  const MPI_Comm comm  = MPI_COMM_WORLD;
  const int      ranks = dealii::Utilities::MPI::n_mpi_processes(comm);
  const bool     root  = dealii::Utilities::MPI::this_mpi_process(comm) == 0;
  const std::string directory =
    std::filesystem::temp_directory_path() / ("mpm_test_point_field_np" + std::to_string(ranks));
  if (root)
    std::filesystem::remove_all(directory);
  MPI_Barrier(comm);

  // Without asking: no array, no column.
  {
    Parameters   p = parameters_from_string(scene(directory + "/plain", 2));
    Simulator<2> simulator(p, comm);
    simulator.setup();
    const HostPoints<2, double> points = simulator.points();
    expect(!points.fields.has(PointField::test_tag) && points.test_tag.empty(),
          "a run that does not ask for test_tag allocates no array for it");
    simulator.finish();
    MPI_Barrier(comm);
    expect(last_tables(directory + "/plain").count("test_tag") == 0, "and writes no test_tag column");
  }

  // Asked for: set once, then followed through steps, sorts, migration and output.
  std::string checkpoint;
  {
    Parameters p = parameters_from_string(scene(directory + "/tagged", 30));
    p.point_fields.insert(PointField::test_tag);
    Simulator<2> simulator(p, comm);
    simulator.setup();
    HostPoints<2, double> points = simulator.points();
    expect(points.fields.has(PointField::test_tag) && points.test_tag.size() == points.mass.size(),
          "a run that asks for test_tag carries one value per point");
    std::set<double> tags_here; // this rank's points at the start
    for (int i = 0; i < points.size(); ++i)
      tags_here.insert(points.test_tag[i] = tag_of(points.position[0][i], points.position[1][i]));
    simulator.set_points(points);
    while (!simulator.finished())
      simulator.advance();
    checkpoint = simulator.write_checkpoint();
    simulator.finish();
    MPI_Barrier(comm);
    int        n    = 0;
    const bool kept = tags_follow_points(last_tables(directory + "/tagged"), n);
    expect(kept, "after 30 steps (sorts every 3, " + std::to_string(ranks) + " rank(s)) each of the " +
                  std::to_string(n) + " points in the tables holds its own tag");
    const HostPoints<2, double> after = simulator.points();
    double moved = 0, arrived = 0;
    for (int i = 0; i < after.size(); ++i)
      {
        moved = std::max(moved, std::abs(after.position[0][i] - after.test_tag[i] / 1000));
        arrived += tags_here.count(after.test_tag[i]) == 0;
      }
    expect(dealii::Utilities::MPI::max(moved, comm) > 0.01, "the points moved (over 1 cm), so the tags travelled");
    if (ranks > 1)
      expect(dealii::Utilities::MPI::sum(arrived, comm) > 0,
             std::to_string(int(dealii::Utilities::MPI::sum(arrived, comm))) +
               " points now on another rank than at the start brought their tags");
  }

  // Resumed from the checkpoint, on as many ranks: the tags come back with their points.
  {
    Parameters p = parameters_from_string(scene(directory + "/tagged", 40));
    p.point_fields.insert(PointField::test_tag);
    Simulator<2> simulator(p, comm);
    simulator.resume(checkpoint);
    while (!simulator.finished())
      simulator.advance();
    simulator.finish();
    MPI_Barrier(comm);
    int        n    = 0;
    const bool kept = tags_follow_points(last_tables(directory + "/tagged"), n);
    expect(kept, "resumed from the checkpoint, 10 steps more: each of the " + std::to_string(n) +
                  " points in the tables holds its own tag");
  }

  MPI_Barrier(comm);
  if (root)
    std::filesystem::remove_all(directory);
  }
  catch (const std::exception &e)
  {
    std::printf("unexpected exception: %s\n", e.what());
    return 1;
  }
  return mpm_test::finish("test_point_field");
}
