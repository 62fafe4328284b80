#include <mpm/dealii/checkpoint.h>

#include <deal.II/base/exceptions.h>
#include <deal.II/base/mpi.h>
#include <deal.II/base/utilities.h>

#include <boost/archive/binary_iarchive.hpp>
#include <boost/archive/binary_oarchive.hpp>
#include <boost/serialization/string.hpp>
#include <boost/serialization/utility.hpp>
#include <boost/serialization/vector.hpp>

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <sstream>

namespace mpm
{
  namespace fs = std::filesystem;

  template <class Archive>
  void RunState::serialize(Archive &archive, const unsigned int /*version*/)
  {
    archive &dim &n_ranks &lower &upper &cell_size &n_materials &state_variable_names &strength_divisor;
    archive &time &dt &max_speed &max_removed_speed &work_of_gravity &elastic_wave_speed &smallest_point_mass
      &balanced &next_output;
    archive &step &n_points_initial &n_removed &n_resorts &n_repartitions &n_sent &plastic;
    archive &initial_mass &dropped_mass &n_dropped;
    archive &equilibration.steps &equilibration.wall_seconds &equilibration.reference_speed
      &equilibration.final_speed &equilibration.max_stress_change &equilibration.rms_stress_change;
    archive &n_outputs &grid_records &particle_records;
  }

  namespace checkpoint
  {
    namespace
    {
      // Marks the files of this format; a file of another kind or version is refused.
      // Format 2 (2026-12-03): the run's strength divisor (a pre-failure hand-over's).
      // Format 3 (2026-12-07): the points' fields by name (point_fields.h), each array after its name.
      constexpr unsigned int format = 0x4d504d03, format_2 = 0x4d504d02, format_1 = 0x4d504d01; // "MPM" 3, 2, 1

      // Refuses a file of another format, naming it.
      void check_format(const unsigned int magic, const std::string &file)
      {
        for (const auto &[old, since] : {std::pair<unsigned int, const char *>{format_1, "2026-12-03"},
                                         std::pair<unsigned int, const char *>{format_2, "2026-12-07"}})
          AssertThrow(magic != old,
                      dealii::ExcMessage("--resume: '" + file + "' was written by an earlier dealii-mpm (checkpoint "
                                         "format " + std::to_string(old & 0xff) + ", before " + since +
                                         "), which this one does not read: resume it with the version that wrote it."));
        AssertThrow(magic == format,
                    dealii::ExcMessage("--resume: '" + file + "' is not a dealii-mpm checkpoint file."));
      }

      const std::string partial_suffix = ".partial";

      // Flushes a written file (or folder) to the disk: a checkpoint renamed complete
      // must survive a crash of the machine right after.
      void sync_to_disk(const std::string &path)
      {
        const int fd = ::open(path.c_str(), O_RDONLY);
        if (fd >= 0)
          {
            ::fsync(fd);
            ::close(fd);
          }
      }

      std::string points_file(const std::string &folder, const unsigned int rank)
      {
        return folder + "/points." + std::to_string(rank);
      }

      // The step of a complete checkpoint's folder name, or -1.
      long step_of(const fs::path &folder)
      {
        const std::string name = folder.filename().string();
        const std::string head = "checkpoint-";
        if (name.size() <= head.size() || name.compare(0, head.size(), head) != 0)
          return -1;
        const std::string digits = name.substr(head.size());
        if (!std::all_of(digits.begin(), digits.end(), [](const char c) { return c >= '0' && c <= '9'; }))
          return -1;
        return fs::exists(folder / "run.state") ? std::stol(digits) : -1;
      }

      // Complete checkpoints in directory, oldest first.
      std::vector<std::pair<long, fs::path>> complete_checkpoints(const std::string &directory)
      {
        std::vector<std::pair<long, fs::path>> found;
        std::error_code                        error;
        for (const auto &entry : fs::directory_iterator(directory, error))
          if (entry.is_directory() && step_of(entry.path()) >= 0)
            found.emplace_back(step_of(entry.path()), entry.path());
        std::sort(found.begin(), found.end());
        return found;
      }

      // Stops every rank where one failed, with the first failing rank's message.
      void check_everywhere(const std::string &problem, MPI_Comm communicator)
      {
        const unsigned int n_ranks = dealii::Utilities::MPI::n_mpi_processes(communicator);
        if (n_ranks == 1)
          {
            AssertThrow(problem.empty(), dealii::ExcMessage(problem));
            return;
          }
        const auto all = dealii::Utilities::MPI::all_gather(communicator, problem);
        for (const std::string &p : all)
          AssertThrow(p.empty(), dealii::ExcMessage(p));
      }

      template <int dim>
      void write_points(const std::string &file, const PointSnapshot<dim> &snapshot)
      {
        std::ofstream out(file, std::ios::binary);
        AssertThrow(out, dealii::ExcMessage("cannot write '" + file + "'"));
        {
          boost::archive::binary_oarchive archive(out);
          const unsigned int              dimension = dim;
          int                             n = snapshot.points.size(), n_state_variables = snapshot.points.n_state_variables();
          archive << format << dimension << n << n_state_variables << snapshot.labels->state_variable_names;
          std::vector<std::string> fields;
          for_each_core_field(snapshot.points, [&](const PointField field, const auto &) {
            if (snapshot.points.fields.has(field))
              fields.push_back(info(field).member);
          });
          archive << fields;
          for_each_core_field(snapshot.points, [&](const PointField field, const auto &member) {
            if (snapshot.points.fields.has(field))
              for_each_array_of(member, [&](const auto &array) { archive << array; });
          });
          for (const auto &array : snapshot.points.state_variables)
            archive << array;
          archive << snapshot.labels->id;
          for (int d = 0; d < dim; ++d)
            archive << snapshot.labels->initial_position[d];
        }
        out.close();
        AssertThrow(out, dealii::ExcMessage("writing '" + file + "' failed (disk full?)"));
        sync_to_disk(file);
      }

      // Appends the points of one file for which keep is true to `to` (whose labels are
      // being filled).
      template <int dim>
      void read_points_into(const std::string &file, HostPoints<dim, double> &to, PointLabels<dim> &labels,
                            const std::function<bool(const HostPoints<dim, double> &, int)> &keep)
      {
        std::ifstream in(file, std::ios::binary);
        AssertThrow(in, dealii::ExcMessage("--resume: cannot read '" + file + "'."));
        boost::archive::binary_iarchive archive(in);
        unsigned int                    magic = 0, dimension = 0;
        int                             n = 0, n_state_variables = 0;
        archive >> magic;
        check_format(magic, file);
        archive >> dimension >> n >> n_state_variables;
        std::vector<std::string> names;
        archive >> names;
        AssertThrow(dimension == dim, dealii::ExcMessage("--resume: '" + file + "' holds points of a " +
                                                         std::to_string(dimension) + "D run."));
        // The fields as the file names them, each field's arrays after the list.
        std::vector<std::string> fields;
        archive >> fields;
        HostPoints<dim, double> part;
        std::vector<PointField> order;
        for (const std::string &name : fields)
          {
            int f = 0;
            while (f < n_point_fields && name != point_field_info[f].member)
              ++f;
            AssertThrow(f < n_point_fields, dealii::ExcMessage("--resume: '" + file + "' holds a point field '" + name +
                                                               "' that this dealii-mpm does not know."));
            part.fields.insert(static_cast<PointField>(f));
            order.push_back(static_cast<PointField>(f));
          }
        part.set_n_state_variables(n_state_variables);
        part.resize(n);
        for (const PointField wanted : order)
          for_each_core_field(part, [&](const PointField field, auto &member) {
            if (field == wanted)
              for_each_array_of(member, [&](auto &array) { archive >> array; });
          });
        for (auto &array : part.state_variables)
          archive >> array;
        std::vector<dealii::types::particle_index> id;
        std::vector<double>                        initial_position[dim];
        archive >> id;
        for (int d = 0; d < dim; ++d)
          archive >> initial_position[d];
        labels.state_variable_names = names;
        if (to.size() == 0)
          {
            to.fields = part.fields;
            to.set_n_state_variables(n_state_variables);
          }
        for (int i = 0; i < n; ++i)
          if (keep(part, i))
            {
              const int k = to.size();
              to.resize(k + 1);
              for_each_point_array<dim>(to, part, [&](auto &destination, const auto &origin) { destination[k] = origin[i]; });
              labels.id.push_back(id[i]);
              for (int d = 0; d < dim; ++d)
                labels.initial_position[d].push_back(initial_position[d][i]);
            }
      }
    } // namespace

    std::string folder_name(const long step)
    {
      std::ostringstream name;
      name << "checkpoint-" << std::setw(9) << std::setfill('0') << step;
      return name.str();
    }

    template <int dim>
    std::string write(const std::string &directory, const RunState &state, const PointSnapshot<dim> &points,
                      const unsigned int keep, MPI_Comm communicator)
    {
      const unsigned int rank   = dealii::Utilities::MPI::this_mpi_process(communicator);
      const std::string  final  = directory + "/" + folder_name(state.step);
      const std::string  folder = final + partial_suffix;
      const std::string  where  = "Parameter 'Checkpoint/Directory': ";

      // Rank 0 makes the folder (a partial one left by a run killed while writing goes).
      std::string problem;
      if (rank == 0)
        {
          std::error_code error;
          fs::remove_all(folder, error);
          fs::create_directories(folder, error);
          if (error)
            problem = where + "cannot create '" + folder + "': " + error.message();
        }
      if (state.n_ranks > 1)
        problem = dealii::Utilities::MPI::broadcast(communicator, problem, 0);
      AssertThrow(problem.empty(), dealii::ExcMessage(problem));

      try
        {
          write_points<dim>(points_file(folder, rank), points);
          if (rank == 0)
            {
              const std::string file = folder + "/run.state";
              std::ofstream     out(file, std::ios::binary);
              AssertThrow(out, dealii::ExcMessage("cannot write '" + file + "'"));
              {
                boost::archive::binary_oarchive archive(out);
                archive << format << state;
              }
              out.close();
              AssertThrow(out, dealii::ExcMessage("writing '" + file + "' failed (disk full?)"));
              sync_to_disk(file);
            }
        }
      catch (const std::exception &e)
        {
          problem = where + "MPI rank " + std::to_string(rank) + ": " + e.what();
        }
      check_everywhere(problem, communicator);

      // Every rank has written: rank 0 commits the checkpoint by renaming it, then prunes.
      if (rank == 0)
        {
          std::error_code error;
          sync_to_disk(folder);
          fs::remove_all(final, error); // the same step written before (a resumed run)
          fs::rename(folder, final, error);
          if (error)
            problem = where + "cannot rename '" + folder + "' to '" + final + "': " + error.message();
          sync_to_disk(directory);
          const auto found = complete_checkpoints(directory);
          for (std::size_t k = 0; k + keep < found.size(); ++k)
            fs::remove_all(found[k].second, error);
        }
      if (state.n_ranks > 1)
        problem = dealii::Utilities::MPI::broadcast(communicator, problem, 0);
      AssertThrow(problem.empty(), dealii::ExcMessage(problem));
      return final;
    }

    std::string find(const std::string &path)
    {
      AssertThrow(fs::is_directory(path),
                  dealii::ExcMessage("--resume: '" + path + "' is not a folder. Give a checkpoint folder "
                                     "(checkpoint-NNNNNNNNN) or the folder holding them (Checkpoint/Directory)."));
      if (fs::exists(fs::path(path) / "run.state"))
        return path;
      const auto found = complete_checkpoints(path);
      AssertThrow(!found.empty(),
                  dealii::ExcMessage("--resume: '" + path + "' holds no complete checkpoint (a folder "
                                     "checkpoint-NNNNNNNNN with a file run.state; folders ending in .partial were "
                                     "not finished). Checkpoints are written where Checkpoint/Step interval or "
                                     "Checkpoint/Wall-clock interval asks for them."));
      return found.back().second.string();
    }

    RunState read_state(const std::string &checkpoint)
    {
      const std::string file = checkpoint + "/run.state";
      std::ifstream     in(file, std::ios::binary);
      AssertThrow(in, dealii::ExcMessage("--resume: cannot read '" + file + "'."));
      RunState     state;
      unsigned int magic = 0;
      try
        {
          boost::archive::binary_iarchive archive(in);
          archive >> magic;
          if (magic == format)
            archive >> state;
        }
      catch (const std::exception &e)
        {
          AssertThrow(false, dealii::ExcMessage("--resume: '" + file + "' cannot be read as a dealii-mpm "
                                                "checkpoint (" + e.what() + ")."));
        }
      check_format(magic, file);
      return state;
    }

    template <int dim>
    PointSnapshot<dim> read_points(const std::string &checkpoint, const RunState &state,
                                   const std::function<bool(const HostPoints<dim, double> &, int)> &keep)
    {
      PointSnapshot<dim> snapshot;
      auto               labels = std::make_shared<PointLabels<dim>>();
      try
        {
          for (unsigned int r = 0; r < state.n_ranks; ++r)
            read_points_into<dim>(points_file(checkpoint, r), snapshot.points, *labels, keep);
        }
      catch (const boost::archive::archive_exception &e)
        {
          AssertThrow(false, dealii::ExcMessage("--resume: the points of '" + checkpoint +
                                                "' cannot be read (" + e.what() + "): the checkpoint is damaged."));
        }
      snapshot.labels = std::move(labels);
      return snapshot;
    }

    template std::string write(const std::string &, const RunState &, const PointSnapshot<2> &, unsigned int,
                               MPI_Comm);
    template std::string write(const std::string &, const RunState &, const PointSnapshot<3> &, unsigned int,
                               MPI_Comm);
    template PointSnapshot<2> read_points(const std::string &, const RunState &,
                                          const std::function<bool(const HostPoints<2, double> &, int)> &);
    template PointSnapshot<3> read_points(const std::string &, const RunState &,
                                          const std::function<bool(const HostPoints<3, double> &, int)> &);
  } // namespace checkpoint
} // namespace mpm
