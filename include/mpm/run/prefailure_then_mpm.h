// A run with a pre-failure analysis (Pre-failure analysis/Method != none), as the executable
// does it: the FEM stage (fem/prefailure_analysis.h), then, with Continue with MPM, the MPM from
// the FEM's committed state through the hand-over API (dealii/fem_handover.h, placement (a)) to
// End time: the two layers joined here, exactly as a user's own FEM program would join them.
#pragma once

#include <mpm/run/scene.h>

#include <mpi.h>

#include <functional>
#include <string>

namespace mpm
{
  // before_mpm is called once the MPM's steps are about to start (the executable installs its
  // SIGTERM/SIGINT handlers there: the FEM stage has no checkpoints, and a signal stops it at
  // once). resume_from: a checkpoint of the MPM stage (Simulator::resume); the analysis is then
  // not run again, and the materials' strengths are divided as in the run that wrote it.
  // Returns false where the MPM was stopped on request (request_checkpoint_and_stop) after
  // writing its checkpoint, true otherwise.
  bool run_prefailure_analysis(const Scene &scene, MPI_Comm communicator, const std::string &resume_from = "",
                               const std::function<void()> &before_mpm = {});
} // namespace mpm
