// Backend = cuda (include/mpm/dealii/cuda_engine.h). Compiled by the C++ compiler in
// every build; the device work is in the library mpm_cuda_engine (source/cuda/*.cu),
// linked when the project is configured with -DMPM_WITH_CUDA=ON (MPM_CUDA_ENGINE).
#include <mpm/dealii/cuda_engine.h>

#include <deal.II/base/exceptions.h>

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
      // One rank: no ghost nodes, no exchange. The MPI version will pass a NodalExchange
      // that sums ghost contributions on the device buffers.
      CudaEngine(HostGrid<dim, double> lattice, const std::vector<MaterialParameters<double>> &materials,
                 const ShapeFunction shape)
        : device(make_grid_view<dim, double>(lattice), materials, shape, nullptr)
      {}

      void load(const MaterialPoints<dim> &p) override
      {
        auto new_labels = std::make_shared<PointLabels<dim>>();
        p.copy_to(host, nullptr, new_labels.get());
        load(host, std::move(new_labels));
      }

      void load(const HostPoints<dim, double> &p, std::shared_ptr<const PointLabels<dim>> new_labels) override
      {
        labels = std::move(new_labels); // a snapshot being written keeps the old ones
        device.upload_points(p);
      }

      // Hand-over to the handler (an MPI re-sort; the CUDA engine runs on one rank, where
      // nothing calls it yet): points come back, points that left the grid are removed,
      // the handler's new order goes back down.
      unsigned int store(MaterialPoints<dim> &p) override
      {
        host.resize(device.n_points());
        device.download_points(host);
        const unsigned int removed = p.copy_from(host);
        load(p);
        return removed;
      }

      // Output: the points come down in the order of the last upload (DeviceEngine's
      // contract), which is the labels' order.
      void snapshot(PointSnapshot<dim> &s) override
      {
        s.points.resize(device.n_points());
        device.download_points(s.points);
        s.labels = labels;
      }

      // The device's lattice-ordered nodes into the grid's numbering.
      void nodal_to(BackgroundGrid<dim> &grid) override { device.download_nodal(grid.view()); }

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
      cuda::DeviceEngine<dim>   device;
      HostPoints<dim, double>   host; // staging for load/store from the handler only
      std::shared_ptr<const PointLabels<dim>> labels; // id, initial position, in the uploaded order
    };
  } // namespace
#endif

  bool cuda_engine_built()
  {
#ifdef MPM_CUDA_ENGINE
    return true;
#else
    return false;
#endif
  }

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
  std::unique_ptr<Engine<dim>> make_cuda_engine(const HostGrid<dim, double> &lattice,
                                                const std::vector<MaterialParameters<double>> &materials,
                                                const ShapeFunction shape)
  {
#ifdef MPM_CUDA_ENGINE
    for (const MaterialParameters<double> &m : materials)
      AssertThrow(m.model != MaterialModel::user_defined,
                  dealii::ExcMessage("Parameter 'Backend/Backend': 'cuda' cannot run a constitutive model defined "
                                     "outside the library (UserConstitutiveModel); use 'cpu'."));
    std::string why;
    AssertThrow(cuda::device_count(&why) > 0,
                dealii::ExcMessage("Parameter 'Backend/Backend': 'cuda' was asked for, but no CUDA device is usable (" +
                                   why + "). Use 'cpu', or run on a machine with an NVIDIA GPU and driver."));
    std::cout << "  CUDA device: " << cuda::device_description() << std::endl; // one rank
    return std::make_unique<CudaEngine<dim>>(lattice, materials, shape);
#else
    (void)lattice;
    (void)materials;
    (void)shape;
    AssertThrow(false, dealii::ExcMessage("Parameter 'Backend/Backend': 'cuda' is not available in this build "
                                          "(allowed here: cpu). Configure with -DMPM_WITH_CUDA=ON (needs nvcc) "
                                          "for cuda."));
    return nullptr;
#endif
  }

  template std::unique_ptr<Engine<2>> make_cuda_engine(const HostGrid<2, double> &,
                                                       const std::vector<MaterialParameters<double>> &, ShapeFunction);
  template std::unique_ptr<Engine<3>> make_cuda_engine(const HostGrid<3, double> &,
                                                       const std::vector<MaterialParameters<double>> &, ShapeFunction);
} // namespace mpm
