#include <mpm/dealii/backend_settings.h>

namespace mpm
{
  using dealii::ParameterHandler;
  namespace Patterns = dealii::Patterns;

  void BackendSettings::declare(ParameterHandler &prm)
  {
    prm.declare_entry("Backend", "cpu", Patterns::Selection("cpu|cuda"),
                      "Where the MPM step runs: cpu (threads through TBB) or cuda (needs a build with "
                      "-DMPM_WITH_CUDA=ON and a CUDA device on every rank; on several MPI ranks one GPU per "
                      "rank, chosen by the rank's place on its node, ranks beyond a node's GPUs sharing them).");
    prm.declare_entry("Sort interval", "20", Patterns::Integer(0),
                      "cuda: the device re-sorts its points by stencil every this many steps (0: never), so "
                      "that neighbouring threads add into the same nodes and sum before their atomics. 20 "
                      "measured faster than 50 and than every step on P1; 10, 20 and 40 alike on P2 "
                      "(doc/performance.md).");
    prm.declare_entry("Queue steps", "true", Patterns::Bool(),
                      "cuda on one MPI rank: queue each step on the GPU before the last one has ended, its time "
                      "step computed on the device from the last step's largest speed by the same rule as the "
                      "host's, so that the GPU does not wait for the host between steps (the same steps and time "
                      "steps, checked to the bit), and the steps between two re-sorts launched as one CUDA graph "
                      "each. On an H200 P2's step 2% shorter, V3 2D's 14% (doc/performance.md). false: the host "
                      "waits for each step's speed before it starts the next. Not with Grid/Nodes = near "
                      "material, whose check after each step needs the points where they are.");
    prm.declare_entry("Precision", "double", Patterns::Selection("double|float"),
                      "The floating-point type of the points, the nodes and the step: double, or float (the engine's "
                      "point and node arrays in half the bytes; with Backend = cuda P2's step 1.46x faster, on the CPU "
                      "no faster: doc/performance.md; the results carry float's round-off, about 1e-7 of each value per "
                      "operation, doc/methods.md). float runs with the library's materials, on any number of MPI ranks "
                      "with either backend (the ranks exchange their nodal sums in float). Output, checkpoints and "
                      "the time history are written in double either way.");
  }

  void BackendSettings::parse(ParameterHandler &prm)
  {
    name             = prm.get("Backend");
    sort_interval    = prm.get_integer("Sort interval");
    queue_steps      = prm.get_bool("Queue steps");
    single_precision = prm.get("Precision") == "float";
  }
} // namespace mpm
