#include <mpm/dealii/output_writer.h>

#include <deal.II/base/exceptions.h>
#include <deal.II/base/mpi.h>
#include <deal.II/numerics/data_out.h>
#include <deal.II/particles/data_out.h>

#include <filesystem>
#include <iomanip>
#include <sstream>

namespace mpm
{
  template <int dim>
  OutputWriter<dim>::OutputWriter(const Parameters &parameters, MPI_Comm communicator)
    : communicator(communicator)
    , output_directory(parameters.output_directory)
    , write_grid(parameters.write_grid_fields)
    , write_particles(parameters.write_particles)
    , write_table(parameters.write_particle_table)
  {
    if (output_directory.empty())
      output_directory = ".";
    // Rank 0 creates the folder and the history; every rank learns whether that worked,
    // so that a bad Output/Directory stops all ranks with one message instead of a hang.
    std::string problem;
    if (dealii::Utilities::MPI::this_mpi_process(communicator) == 0)
      {
        std::error_code error;
        std::filesystem::create_directories(output_directory, error);
        if (error)
          problem = "cannot create '" + output_directory + "': " + error.message();
        else
          {
            history.open(output_directory + "/history.csv");
            if (!history)
              problem = "cannot write to '" + output_directory + "'.";
          }
      }
    problem = dealii::Utilities::MPI::broadcast(communicator, problem, 0);
    AssertThrow(problem.empty(), dealii::ExcMessage("Parameter 'Output/Directory': " + problem));
    if (dealii::Utilities::MPI::this_mpi_process(communicator) == 0)
      {
        history << "time,dt,step,kinetic_energy,work_of_gravity,total_mass";
        for (int d = 0; d < dim; ++d)
          history << ",momentum_" << "xyz"[d];
        history << ",n_points,n_removed";
        for (int d = 0; d < dim; ++d)
          history << ",min_" << "xyz"[d];
        for (int d = 0; d < dim; ++d)
          history << ",max_" << "xyz"[d];
        history << ",min_points_per_rank,max_points_per_rank,n_resorts,n_repartitions,n_sent";
        history << "\n" << std::setprecision(16);
      }
  }

  template <int dim>
  void OutputWriter<dim>::write_fields(const double time, BackgroundGrid<dim> &grid, const MaterialPoints<dim> &points)
  {
    const bool root = dealii::Utilities::MPI::this_mpi_process(communicator) == 0;
    if (write_grid)
      {
        dealii::DataOut<dim> out;
        out.attach_dof_handler(grid.dof_handler);
        grid.mass.update_ghost_values();
        out.add_data_vector(grid.mass, "nodal_mass");
        const char *names[3] = {"nodal_velocity_x", "nodal_velocity_y", "nodal_velocity_z"};
        for (int d = 0; d < dim; ++d)
          {
            grid.velocity[d].update_ghost_values();
            out.add_data_vector(grid.velocity[d], names[d]);
          }
        dealii::Vector<float> subdomain(grid.triangulation.n_active_cells());
        subdomain = dealii::Utilities::MPI::this_mpi_process(communicator);
        out.add_data_vector(subdomain, "subdomain");
        out.build_patches();
        const std::string name = out.write_vtu_with_pvtu_record(output_directory + "/", "grid", counter, communicator, 5);
        grid_records.emplace_back(time, name);
        if (root)
          {
            std::ofstream pvd(output_directory + "/grid.pvd");
            dealii::DataOutBase::write_pvd_record(pvd, grid_records);
          }
      }
    if (write_particles)
      {
        dealii::Particles::DataOut<dim> out;
        out.build_patches(points.handler, PropertyLayout<dim>::names(), PropertyLayout<dim>::interpretations());
        const std::string name =
          out.write_vtu_with_pvtu_record(output_directory + "/", "particles", counter, communicator, 5);
        particle_records.emplace_back(time, name);
        if (root)
          {
            std::ofstream pvd(output_directory + "/particles.pvd");
            dealii::DataOutBase::write_pvd_record(pvd, particle_records);
          }
      }
    if (write_table)
      {
        const unsigned int rank = dealii::Utilities::MPI::this_mpi_process(communicator);
        std::ostringstream name;
        name << output_directory << "/particle_table_" << std::setw(5) << std::setfill('0') << counter << '.'
             << rank << ".csv";
        std::ofstream table(name.str());
        AssertThrow(table, dealii::ExcMessage("Parameter 'Output/Directory': cannot write '" + name.str() + "'."));
        const auto names = PropertyLayout<dim>::names();
        table << "id";
        for (int d = 0; d < dim; ++d)
          table << ",position_" << "xyz"[d];
        std::vector<unsigned int> seen(names.size(), 0);
        for (unsigned int k = 0; k < names.size(); ++k)
          {
            // Vector properties repeat their name: number their components.
            unsigned int repeats = 0;
            for (unsigned int j = 0; j < names.size(); ++j)
              repeats += names[j] == names[k];
            table << ',' << names[k];
            if (repeats > 1)
              table << '_' << "xyz"[seen[k]];
            for (unsigned int j = k + 1; j < names.size(); ++j)
              if (names[j] == names[k])
                seen[j] = seen[k] + 1;
          }
        table << '\n' << std::setprecision(17);
        for (const auto &particle : points.handler)
          {
            table << particle.get_id();
            for (int d = 0; d < dim; ++d)
              table << ',' << particle.get_location()[d];
            for (const double value : particle.get_properties())
              table << ',' << value;
            table << '\n';
          }
      }
    ++counter;
  }

  template <int dim>
  void OutputWriter<dim>::write_history(const HistoryRow &r)
  {
    if (dealii::Utilities::MPI::this_mpi_process(communicator) != 0)
      return;
    history << r.time << ',' << r.dt << ',' << r.step << ',' << r.totals.kinetic_energy << ','
            << r.work_of_gravity << ',' << r.totals.mass;
    for (int d = 0; d < dim; ++d)
      history << ',' << r.totals.momentum[d];
    history << ',' << r.totals.n_points << ',' << r.n_removed;
    for (int d = 0; d < dim; ++d)
      history << ',' << r.totals.lower[d];
    for (int d = 0; d < dim; ++d)
      history << ',' << r.totals.upper[d];
    history << ',' << r.min_points_per_rank << ',' << r.max_points_per_rank << ',' << r.n_resorts << ','
            << r.n_repartitions << ',' << r.n_sent;
    history << '\n';
    history.flush();
  }

  template class OutputWriter<2>;
  template class OutputWriter<3>;
} // namespace mpm
