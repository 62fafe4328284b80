// A dealii-mpm run, driven by the executable or by a user's program:
//
//   mpm::Parameters parameters = mpm::read_parameters("scene.prm");  // or filled in C++
//   mpm::Simulator<2> simulator(parameters, MPI_COMM_WORLD);
//   simulator.setup();                       // grid, points, engine; the t = 0 output
//   while (!simulator.finished())
//     simulator.advance();                   // one explicit step, with the outputs it owes
//   simulator.finish();                      // last output, the run's summary
//
// run() does the same, and on one MPI rank starts stepping while deal.II builds its grid and
// ParticleHandler on a thread (that thread calls MPI, so between the calls of a program
// that steps the run itself, setup() finishes the grid first and no thread is left running).
// The points can be read and changed between steps (points(), set_points()).
#pragma once

#include <mpm/core/host_storage.h>
#include <mpm/dealii/material_points.h>
#include <mpm/dealii/parameters.h>

#include <mpi.h>

#include <memory>
#include <string>
#include <vector>

namespace mpm
{
  // What setup()'s equilibration did (Initial state/Equilibrate): damped steps at t = 0,
  // gravity in full, the points held in place, until the grid's velocities vanish: the
  // stresses then balance gravity in the MPM's own discretisation of the geometry given.
  // And how far that moved the stresses. steps = 0: no equilibration.
  struct EquilibrationReport
  {
    long   steps             = 0; // damped steps taken
    double wall_seconds      = 0;
    double reference_speed   = 0; // sqrt(|g| H), H the extent of the points' domains along gravity (m/s)
    double final_speed       = 0; // largest point speed at the end (m/s), below tolerance x reference_speed
    double max_stress_change = 0; // largest change of a stress component of a point (Pa)
    double rms_stress_change = 0; // root mean square over the points of their largest change (Pa)
  };

  template <int dim>
  class Simulator
  {
  public:
    Simulator(const Parameters &parameters, MPI_Comm communicator);
    // Waits for output still being written; prints the timing summary.
    ~Simulator();

    // Builds the background grid, the material points and the engine (Backend), equilibrates
    // the points where Initial state/Equilibrate asks for it, and writes the t = 0 output and
    // history row. Throws naming the parameter on bad input.
    void setup();
    // The same with the points of `bodies` instead of the prm's bodies (Material points): a
    // state handed over from elsewhere, e.g. an FEM analysis (fem_handover.h). Every point
    // must lie inside the grid and name one of the prm's materials (by index, Materials/Names
    // order); the elastic wave speed of the time step comes from the points' own density.
    // On several ranks each rank gives its own points (those of its FEM cells); they are
    // gathered, and each rank keeps those in its MPM cells. The points' ids follow their
    // positions (lexicographic order, x first), on any number of ranks.
    void setup(std::vector<GeneratedBody<dim>> bodies);
    // One explicit step of the scheme, then the history row and output due after it.
    // Returns the time step taken. Throws if the run has become unstable.
    double advance();
    // True once End time (or Maximum number of steps) is reached.
    bool finished() const;
    // Writes the last output (if not yet written at this time), waits for the output files
    // and prints the run's summary.
    void finish();
    // setup(), advance() until finished(), finish().
    void run();

    // Instead of setup(): continues the run from a checkpoint (doc/checkpoints.md): the
    // folder of one (checkpoint-NNNNNNNNN) or the folder holding them (the newest complete one
    // is taken), written by a run of the same scene on any number of ranks. The grid, the
    // materials' names and Parameters::strength_divisor must be the prm's; End time, output,
    // checkpoint and solver settings may differ and apply from the resumed step on. On as many
    // ranks as wrote it (CPU), the resumed run ends bit-identical to the run that was not stopped.
    void resume(const std::string &checkpoint);
    // Writes a checkpoint of the run as it is after the last step, collectively, into
    // Checkpoint/Directory, and returns its folder. advance() writes them where Checkpoint
    // asks for them. On several ranks it re-sorts the points into cells and ranks first.
    std::string write_checkpoint();
    // True once a stop was requested (request_checkpoint_and_stop) and advance() has written
    // the checkpoint for it; finished() is then true, and finish() reports the stop.
    bool stopped() const;

    double time() const;
    long   step() const;
    // The equilibration's numbers (steps = 0 where Initial state/Equilibrate is false).
    const EquilibrationReport &equilibration() const;
    const Parameters &parameters() const;

    // The material points as the engine holds them now, in the engine's order; points that
    // have left the grid are included with material < 0. Every field of the core's point
    // arrays (HostPoints): position, velocity, mass, volume, stress, strain, F, ...
    HostPoints<dim, double> points() const;
    // Replaces the points' values: the same points in the same order (as points() gave
    // them), any field changed. On several MPI ranks, collective: each rank gives its own
    // points; those moved into another rank's cells migrate there (points() then returns
    // the new partition's). A point outside the grid is refused.
    void set_points(const HostPoints<dim, double> &points);

  private:
    struct State;
    void setup(bool grid_beside_first_steps, std::vector<GeneratedBody<dim>> *given_bodies);
    std::unique_ptr<State> state;
  };

  // Asks the running Simulator of this process to write a checkpoint after its current step
  // and stop (stopped()); its finish() clears the request, so that a Simulator made later
  // runs on. Async-signal-safe: the executable calls it on SIGTERM and SIGINT. On several
  // ranks the first rank asked stops all of them at the same step.
  void request_checkpoint_and_stop();

  // Runs the simulator of the parameter file's dimension (the executable), from the
  // checkpoint `resume_from` where it is not empty. Returns false where the run was stopped
  // (request_checkpoint_and_stop) before its end, true where it ran to the end.
  bool run_simulation(const Parameters &parameters, MPI_Comm communicator, const std::string &resume_from = "");
} // namespace mpm
