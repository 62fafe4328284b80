#include <mpm/core/backend/cpu_backend.h>
#include <mpm/core/migration.h>
#include <mpm/dealii/cuda_engine.h>
#include <mpm/dealii/engine.h>

#include <deal.II/base/exceptions.h>

namespace mpm
{
  namespace
  {
    template <int dim>
    class CpuEngine : public Engine<dim>
    {
    public:
      CpuEngine(BackgroundGrid<dim> &grid, const std::vector<MaterialParameters<double>> &materials,
                const ShapeFunction shape)
        : grid(grid)
        , materials(materials)
        , shape(shape)
      {
        long n_cells = 1;
        for (int d = 0; d < dim; ++d)
          n_cells *= grid.n_cells[d];
        cell_volume.assign(n_cells, 0.);
        cell_pressure_volume.assign(n_cells, 0.);
      }

      void load(const MaterialPoints<dim> &p) override
      {
        auto new_labels = std::make_shared<PointLabels<dim>>();
        p.copy_to(points, &home_cells, new_labels.get());
        labels = std::move(new_labels); // a snapshot being written keeps the old ones
      }

      unsigned int store(MaterialPoints<dim> &p) override
      {
        const unsigned int removed = p.copy_from(points);
        load(p); // the handler re-sorted them: take the new order
        return removed;
      }

      // The grid's vectors are the engine's nodal arrays: already up to date.
      void snapshot(PointSnapshot<dim> &s) override
      {
        s.points = points;
        s.labels = labels;
      }

      double max_distance_outside_home_cells() override
      {
        const auto   view = points.view();
        const long  *home = home_cells.data();
        const double h    = grid.h;
        double       origin[dim];
        int          n_cells[dim];
        for (int d = 0; d < dim; ++d)
          {
            origin[d]  = grid.origin[d];
            n_cells[d] = grid.n_cells[d];
          }
        return backend.reduce_points(
          view.n_points, 0.0,
          [&](const int i) {
            return view.material[i] < 0 ? 0.0 :
                                          distance_outside_home_cell<dim>(origin, h, n_cells, view.position,
                                                                          home[i], i);
          },
          [](const double a, const double b) { return a > b ? a : b; });
      }

      StepReduction<double> step(const StepSettings<dim, double> &s, const double dt) override
      {
        GridView<dim, double> g  = grid.view();
        g.cell_volume            = cell_volume.data();
        g.cell_pressure_volume   = cell_pressure_volume.data();
        return explicit_step<dim>(backend, shape, g, points.view(), materials.data(), s, dt, grid.exchange());
      }

      PointTotals<dim, double> totals() override { return point_totals<dim>(backend, points.view()); }

      void set_materials(const std::vector<MaterialParameters<double>> &m) override { materials = m; }

    private:
      BackgroundGrid<dim>                    &grid;
      std::vector<MaterialParameters<double>> materials;
      ShapeFunction                           shape;
      CpuBackend                              backend;
      HostPoints<dim, double>                 points;
      std::vector<long>                       home_cells; // lattice cell of each point at the last sort
      std::shared_ptr<const PointLabels<dim>> labels;     // id, initial position, in the order of points
      std::vector<double>                     cell_volume, cell_pressure_volume; // pressure-averaging scratch
    };
  } // namespace

  template <int dim>
  std::unique_ptr<Engine<dim>> make_engine(const std::string &backend, BackgroundGrid<dim> &grid,
                                           const std::vector<MaterialParameters<double>> &materials,
                                           const ShapeFunction shape)
  {
    if (backend == "cpu")
      return std::make_unique<CpuEngine<dim>>(grid, materials, shape);
    if (backend == "cuda")
      return make_cuda_engine<dim>(grid, materials, shape); // throws where not available
    AssertThrow(false, dealii::ExcMessage("Parameter 'Backend/Backend': '" + backend +
                                          "' is not available in this build (allowed here: cpu). Build with "
                                          "-DMPM_WITH_CUDA=ON for cuda."));
    return nullptr;
  }

  template std::unique_ptr<Engine<2>> make_engine(const std::string &, BackgroundGrid<2> &,
                                                  const std::vector<MaterialParameters<double>> &, ShapeFunction);
  template std::unique_ptr<Engine<3>> make_engine(const std::string &, BackgroundGrid<3> &,
                                                  const std::vector<MaterialParameters<double>> &, ShapeFunction);
} // namespace mpm
