// Backend = cuda (include/mpm/dealii/cuda_engine.h). Compiled by the C++ compiler in
// every build; the device work is in the library mpm_cuda_engine (source/cuda/*.cu),
// linked when the project is configured with -DMPM_WITH_CUDA=ON (MPM_CUDA_ENGINE).
#include <mpm/dealii/cuda_engine.h>

#include <deal.II/base/exceptions.h>
#include <deal.II/base/mpi.h>

#ifdef MPM_CUDA_ENGINE
#  include <mpm/cuda/device_engine.h>

#  include <iostream>
#endif

namespace mpm
{
#ifdef MPM_CUDA_ENGINE
  namespace
  {
    template <int dim>
    class CudaEngine : public Engine<dim>
    {
    public:
      CudaEngine(BackgroundGrid<dim> &grid, const std::vector<MaterialParameters<double>> &materials,
                 const ShapeFunction shape)
        : grid(grid)
        // One rank: no ghost nodes, no exchange. The MPI version passes a NodalExchange
        // that sums ghost contributions on the device buffers here.
        , device(grid.view(), materials, shape, nullptr)
      {}

      void load(const MaterialPoints<dim> &p) override
      {
        auto new_labels = std::make_shared<PointLabels<dim>>();
        p.copy_to(host, nullptr, new_labels.get());
        labels = std::move(new_labels); // a snapshot being written keeps the old ones
        device.upload_points(host);
      }

      // End of run: points come back, points that left the grid are removed, the
      // handler's new order goes back down.
      unsigned int store(MaterialPoints<dim> &p) override
      {
        device.download_points(host);
        const unsigned int removed = p.copy_from(host);
        load(p);
        return removed;
      }

      // Output: points and nodal fields come down; the device keeps the points in the
      // order of the last upload (DeviceEngine's contract), which is the labels' order.
      void snapshot(PointSnapshot<dim> &s) override
      {
        s.points.resize(host.size());
        device.download_points(s.points);
        device.download_nodal(grid.view());
        s.labels = labels;
      }

      StepReduction<double> step(const StepSettings<dim, double> &s, const double dt) override
      {
        return device.step(s, dt);
      }

      PointTotals<dim, double> totals() override { return device.totals(); }

      // For the MPI re-sort; the simulator asks only on more than one rank, which this
      // engine refuses for now.
      double max_distance_outside_home_cells() override
      {
        AssertThrow(false, dealii::ExcMessage("Backend = cuda runs on one MPI rank only for now: points do not "
                                              "migrate between ranks on the device yet."));
        return 0;
      }

      void set_materials(const std::vector<MaterialParameters<double>> &m) override { device.set_materials(m); }

      void set_sort_interval(const int steps) override { device.set_sort_interval(steps); }

    private:
      BackgroundGrid<dim>      &grid;
      cuda::DeviceEngine<dim>   device;
      HostPoints<dim, double>   host; // staging for load/store only
      std::shared_ptr<const PointLabels<dim>> labels; // id, initial position, in the uploaded order
    };
  } // namespace
#endif

  std::future<void> start_cuda_initialisation()
  {
#ifdef MPM_CUDA_ENGINE
    return std::async(std::launch::async, [] { cuda::initialise_device(); });
#else
    std::promise<void> nothing_to_do;
    nothing_to_do.set_value();
    return nothing_to_do.get_future();
#endif
  }

  template <int dim>
  std::unique_ptr<Engine<dim>> make_cuda_engine(BackgroundGrid<dim> &grid,
                                                const std::vector<MaterialParameters<double>> &materials,
                                                const ShapeFunction shape)
  {
#ifdef MPM_CUDA_ENGINE
    std::string why;
    AssertThrow(cuda::device_count(&why) > 0,
                dealii::ExcMessage("Parameter 'Backend/Backend': 'cuda' was asked for, but no CUDA device is usable (" +
                                   why + "). Use 'cpu', or run on a machine with an NVIDIA GPU and driver."));
    AssertThrow(dealii::Utilities::MPI::n_mpi_processes(grid.communicator) == 1,
                dealii::ExcMessage("Parameter 'Backend/Backend': 'cuda' runs on one MPI rank only for now."));
    if (dealii::Utilities::MPI::this_mpi_process(grid.communicator) == 0)
      std::cout << "  CUDA device: " << cuda::device_description() << std::endl;
    return std::make_unique<CudaEngine<dim>>(grid, materials, shape);
#else
    (void)grid;
    (void)materials;
    (void)shape;
    AssertThrow(false, dealii::ExcMessage("Parameter 'Backend/Backend': 'cuda' is not available in this build "
                                          "(allowed here: cpu). Configure with -DMPM_WITH_CUDA=ON (needs nvcc) "
                                          "for cuda."));
    return nullptr;
#endif
  }

  template std::unique_ptr<Engine<2>> make_cuda_engine(BackgroundGrid<2> &,
                                                       const std::vector<MaterialParameters<double>> &, ShapeFunction);
  template std::unique_ptr<Engine<3>> make_cuda_engine(BackgroundGrid<3> &,
                                                       const std::vector<MaterialParameters<double>> &, ShapeFunction);
} // namespace mpm
