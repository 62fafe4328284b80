// dealii-mpm: explicit material point method for large deformation of soils.
//   dealii-mpm scene.prm              run a scene
//   dealii-mpm scene.prm --resume DIR continue it from a checkpoint
//   dealii-mpm scene.prm --check      check it without running it (run_forecast.h)
//   dealii-mpm --print-parameters [2|3] [prm|description|json]
//   dealii-mpm --help
#include <mpm/dealii/run_forecast.h>
#include <mpm/dealii/simulator.h>
#include <mpm/run/prefailure_then_mpm.h>
#include <mpm/run/scene.h>

#include <deal.II/base/mpi.h>

#include <csignal>
#include <cstdlib>
#include <iostream>
#include <string>

namespace
{
  void print_help(std::ostream &out)
  {
    out << "dealii-mpm: explicit material point method (MUSL/USL/USF; linear, GIMP, B-spline and CPDI shape\n"
           "functions) on a deal.II background grid, for elasto-plastic large deformation of soils.\n\n"
           "Usage:\n"
           "  dealii-mpm scene.prm                 run the scene described by a parameter file\n"
           "  mpirun -np N dealii-mpm scene.prm    the same on N MPI ranks\n"
           "  dealii-mpm scene.prm --resume DIR    continue the scene from a checkpoint: DIR is one\n"
           "                                       (checkpoint-NNNNNNNNN) or the folder holding them\n"
           "                                       (Checkpoint/Directory; the newest is taken), on any\n"
           "                                       number of ranks\n"
           "  dealii-mpm scene.prm --check         check the scene without running it: the grid, the\n"
           "                                       points, the first time step and the steps it predicts,\n"
           "                                       the outputs and the memory it would take\n"
           "  dealii-mpm --print-parameters [2|3] [prm|description|json]\n"
           "                                       print every parameter with its default and documentation\n"
           "  dealii-mpm --help                    this text\n"
           "SIGTERM or SIGINT (Ctrl-C) during the steps: a checkpoint is written after the current step and\n"
           "the run stops with exit status 75; a second signal stops it at once. A pre-failure FEM analysis\n"
           "has no checkpoints (a signal stops it at once); its MPM stage has, and --resume continues that\n"
           "stage without the analysis.\n";
  }

  // The exit status of a run stopped by SIGTERM/SIGINT after writing its checkpoint
  // (sysexits.h's EX_TEMPFAIL: try again, here with --resume).
  constexpr int exit_stopped = 75;

  // The first signal asks for a checkpoint and a stop after the current step; a second
  // one (an impatient Ctrl-C) ends the process at once, as without this handler.
  extern "C" void stop_after_checkpoint(const int signal)
  {
    static volatile std::sig_atomic_t received = 0;
    if (received)
      {
        std::signal(signal, SIG_DFL);
        std::raise(signal);
        return;
      }
    received = 1;
    mpm::request_checkpoint_and_stop();
  }
} // namespace

int main(int argc, char **argv)
{
  // Started without a launcher, Open MPI runs one rank as a singleton but still probes the
  // network (UCX) and starts a helper daemon: 0.3 s of MPI_Init on the VM. One rank needs
  // neither; settings given by the user win (setenv without overwrite).
  if (!std::getenv("OMPI_COMM_WORLD_SIZE") && !std::getenv("PMIX_RANK") && !std::getenv("PMI_RANK"))
    {
      setenv("OMPI_MCA_ess_singleton_isolated", "1", 0);
      setenv("OMPI_MCA_pml", "ob1", 0);
    }
  dealii::Utilities::MPI::MPI_InitFinalize mpi(argc, argv, dealii::numbers::invalid_unsigned_int);
  const bool root = dealii::Utilities::MPI::this_mpi_process(MPI_COMM_WORLD) == 0;
  try
    {
      const std::string first = argc > 1 ? argv[1] : "";
      if (first == "--help" || first == "-h")
        {
          if (root)
            print_help(std::cout);
          return 0;
        }
      if (first == "--print-parameters")
        {
          const std::string dim   = argc > 2 ? argv[2] : "2";
          const std::string style = argc > 3 ? argv[3] : "prm";
          if (argc > 4 || (dim != "2" && dim != "3") ||
              (style != "prm" && style != "description" && style != "json"))
            {
              if (root)
                {
                  std::cerr << "dealii-mpm: error: --print-parameters takes a dimension 2 or 3 and a style prm, "
                               "description or json, got '";
                  for (int a = 2; a < argc; ++a)
                    std::cerr << (a > 2 ? " " : "") << argv[a];
                  std::cerr << "'.\n\n";
                  print_help(std::cerr);
                }
              return 2;
            }
          if (root)
            mpm::print_scene_parameters(std::cout, std::stoi(dim), style);
          return 0;
        }
      // scene.prm, scene.prm --resume DIR (either order), or scene.prm --check.
      std::string prm, resume;
      bool        check       = false;
      bool        well_formed = argc == 2 || argc == 3 || argc == 4;
      for (int a = 1; a < argc && well_formed; ++a)
        {
          const std::string arg = argv[a];
          if (arg == "--resume" && a + 1 < argc && resume.empty())
            resume = argv[++a];
          else if (arg == "--check" && !check)
            check = true;
          else if (!arg.empty() && arg[0] != '-' && prm.empty())
            prm = arg;
          else
            well_formed = false;
        }
      if (!well_formed || prm.empty() || (argc == 4 && resume.empty()) || (argc == 3 && !check))
        {
          if (root)
            {
              std::cerr << "dealii-mpm: error: the command line is not one of the forms below.\n\n";
              print_help(std::cerr);
            }
          return 2;
        }
      const mpm::Scene      scene      = mpm::read_scene(prm);
      const bool            prefailure = scene.prefailure.analysis != mpm::fem::Analysis::none;
      const mpm::Parameters &parameters = scene.mpm;
      if (check)
        {
          mpm::print_run_forecast(std::cout, parameters, MPI_COMM_WORLD, prefailure);
          return 0;
        }
      const auto            catch_signals = [] {
        std::signal(SIGTERM, stop_after_checkpoint);
        std::signal(SIGINT, stop_after_checkpoint);
      };
      // A pre-failure analysis has no checkpoints: a signal stops it at once, and only its MPM
      // stage catches signals (and is resumed without the analysis).
      bool ran_to_end = true;
      if (prefailure)
        ran_to_end = mpm::run_prefailure_analysis(scene, MPI_COMM_WORLD, resume, catch_signals);
      else
        {
          catch_signals();
          ran_to_end = mpm::run_simulation(parameters, MPI_COMM_WORLD, resume);
        }
      if (!ran_to_end)
        {
          if (root)
            std::cout << "  continue with: dealii-mpm " << prm << " --resume " << parameters.checkpoint.directory
                      << std::endl;
          return exit_stopped;
        }
    }
  catch (const dealii::ExceptionBase &e)
    {
      if (root)
        {
          std::cerr << "\ndealii-mpm: error\n";
          e.print_info(std::cerr);
          std::cerr << std::endl;
        }
      return 1;
    }
  catch (const std::exception &e)
    {
      if (root)
        std::cerr << "\ndealii-mpm: error: " << e.what() << std::endl;
      return 1;
    }
  return 0;
}
