// The particle output written from the engine's arrays (PointSnapshot + PointDataOut,
// output_writer.h) is the same file as deal.II's Particles::DataOut writes from the
// ParticleHandler after a hand-over, byte for byte (date line off), in 2D and 3D:
//  - every property set to a distinct value per point and property (so that a swapped
//    or missing property in PointSnapshot::properties changes the file), two state
//    variables of a user model among them;
//  - a point that left the grid (material < 0 in the engine) is missing from the patches,
//    as it is from the handler after the hand-over removes it (same patches by id);
//  - the .pvtu records are the same;
//  - pieces of consecutive point ranges (Output/Files per rank) add up to the whole, and an
//    empty piece is a valid file.
// The grid files (GridSnapshot + GridDataOut) are the same file as deal.II's DataOut writes
// for the nodal vectors and the rank as cell data, byte for byte, and their pieces add up
// to the whole.
// Runs on any number of MPI ranks (each rank compares its own piece).
#include <mpm/dealii/material_library.h>
#include <mpm/dealii/material_points.h>
#include <mpm/dealii/output_writer.h>

#include <deal.II/base/mpi.h>
#include <deal.II/numerics/data_out.h>
#include <deal.II/particles/data_out.h>

#include "../core/check.h"
#include "box_scene.h"

#include <algorithm>
#include <iterator>
#include <sstream>

namespace
{
  using namespace mpm;

  // Makes get_patches() public.
  template <typename DataOut>
  struct Exposed : DataOut
  {
    using DataOut::get_patches;
  };

  // The patches sorted by their first data component, the particle id.
  template <typename Patch>
  std::vector<const Patch *> by_id(const std::vector<Patch> &patches)
  {
    std::vector<const Patch *> sorted;
    for (const auto &patch : patches)
      sorted.push_back(&patch);
    std::sort(sorted.begin(), sorted.end(), [](const Patch *a, const Patch *b) { return a->data(0, 0) < b->data(0, 0); });
    return sorted;
  }

  // Whether the patches of two pieces, one after the other, are those of the whole
  // (every vertex and every value).
  template <typename Out>
  bool pieces_make_whole(const Out &first, const Out &second, const Out &whole)
  {
    const auto &a = first.get_patches(), &b = second.get_patches(), &all = whole.get_patches();
    bool        same = a.size() + b.size() == all.size();
    for (unsigned int i = 0; same && i < all.size(); ++i)
      {
        const auto &piece = i < a.size() ? a[i] : b[i - a.size()];
        same = std::equal(std::begin(piece.vertices), std::end(piece.vertices), std::begin(all[i].vertices)) &&
               piece.data == all[i].data;
      }
    return same;
  }

  // A user model whose points carry two state variables (their values are set by hand here).
  class TwoStateVariables : public UserConstitutiveModel
  {
  public:
    std::vector<StateVariable> state_variables() const override { return {{"void_ratio", 0.6}, {"damage", 0}}; }
    void update_stress(const SymTensor<double> &, const Mat3<double> &, bool, SymTensor<double> &, double &,
                       double *) const override
    {}
    LinearElasticParameters<double> elastic_parameters() const override { return {1e6, 0.3}; }
  };

  template <int dim>
  Parameters scene()
  {
    Parameters p      = mpm_test::box_domain<dim>(0.08, 0.01);
    p.bodies          = {mpm_test::box_body<dim>(0.01, 0.05, 2, 2000)};
    p.body_material   = {0};
    p.materials       = {user_defined_material(std::make_shared<TwoStateVariables>())};
    p.material_fields.resize(1);
    return p;
  }

  template <int patch_dim, int spacedim>
  std::string vtu(dealii::DataOutInterface<patch_dim, spacedim> &out)
  {
    dealii::DataOutBase::VtkFlags flags;
    flags.print_date_and_time = false;
    flags.compression_level   = dealii::DataOutBase::VtkFlags::best_speed;
    out.set_flags(flags);
    std::ostringstream s;
    out.write_vtu(s);
    return s.str();
  }

  template <int patch_dim, int spacedim>
  std::string pvtu(dealii::DataOutInterface<patch_dim, spacedim> &out)
  {
    std::ostringstream s;
    out.write_pvtu_record(s, {"particles_00000.0.vtu"});
    return s.str();
  }

  // Grid output: distinct nodal values per DoF and field, DataOut against GridDataOut.
  template <int dim>
  void check_grid(BackgroundGrid<dim> &grid)
  {
    const unsigned int rank = dealii::Utilities::MPI::this_mpi_process(MPI_COMM_WORLD);
    auto fill = [](auto &vector, const double field) {
      for (const auto i : vector.locally_owned_elements())
        vector(i) = field + 0.25 * i + 1e-3 * (i % 7);
      vector.update_ghost_values();
    };
    fill(grid.mass, 1000);
    for (int d = 0; d < dim; ++d)
      fill(grid.velocity[d], -100.0 * (d + 1));

    dealii::DataOut<dim> reference;
    reference.attach_dof_handler(grid.dof_handler);
    reference.add_data_vector(grid.mass, "nodal_mass");
    const char *names[3] = {"nodal_velocity_x", "nodal_velocity_y", "nodal_velocity_z"};
    for (int d = 0; d < dim; ++d)
      reference.add_data_vector(grid.velocity[d], names[d]);
    dealii::Vector<float> subdomain(grid.triangulation.n_active_cells());
    subdomain = rank;
    reference.add_data_vector(subdomain, "subdomain");
    reference.build_patches();

    const GridSnapshot<dim> snapshot(grid, rank);
    GridDataOut<dim>        direct;
    direct.build_patches(snapshot);
    mpm_test::check(snapshot.cells.size() > 4, "the grid has cells on this rank");
    mpm_test::check(vtu(reference) == vtu(direct), dim == 2 ? "2D: same grid .vtu as DataOut's" :
                                                              "3D: same grid .vtu as DataOut's");

    const int                 n = snapshot.cells.size();
    Exposed<GridDataOut<dim>> whole, first, second;
    whole.build_patches(snapshot);
    first.build_patches(snapshot, 0, n / 3);
    second.build_patches(snapshot, n / 3, n);
    mpm_test::check(pieces_make_whole(first, second, whole), "two grid pieces hold the cells of the whole, in order");
  }

  template <int dim>
  void check_dim()
  {
    const Parameters    parameters = scene<dim>();
    BackgroundGrid<dim> grid(parameters, MPI_COMM_WORLD);
    MaterialPoints<dim> points(grid, parameters);
    points.generate(parameters);
    const PropertyLayout<dim>      &layout      = points.layout;
    const std::vector<std::string> &state_names = points.state_variable_names;
    mpm_test::check(state_names == std::vector<std::string>{"void_ratio", "damage"},
                    "the points carry the model's two state variables");

    // Distinct values: point id and property index both show in each value; the
    // material id stays an integer (the engine holds it as int).
    for (auto &particle : points.handler)
      {
        auto properties = particle.get_properties();
        for (unsigned int k = 0; k < layout.n_properties(); ++k)
          properties[k] = 1000.0 * (k + 1) + 0.37 * particle.get_id() + 1e-3 * k * k;
        properties[layout.offset(PointField::material)] = 3;
      }

    // Old path: the handler through Particles::DataOut.
    dealii::Particles::DataOut<dim> from_handler;
    from_handler.build_patches(points.handler, layout.names(), layout.interpretations());
    // New path: the core's arrays (as the engine loads them) through PointDataOut.
    PointSnapshot<dim> snapshot;
    auto               labels = std::make_shared<PointLabels<dim>>();
    points.copy_to(snapshot.points, nullptr, labels.get());
    snapshot.labels = labels;
    PointDataOut<dim> from_snapshot;
    from_snapshot.build_patches(snapshot);

    const std::string a = vtu(from_handler), b = vtu(from_snapshot);
    mpm_test::check(points.handler.n_locally_owned_particles() > 10, "the scene has points on this rank");
    mpm_test::check(a == b, dim == 2 ? "2D: same .vtu from the handler and from the snapshot" :
                                       "3D: same .vtu from the handler and from the snapshot");
    mpm_test::check(pvtu(from_handler) == pvtu(from_snapshot), "same .pvtu record");

    // Pieces (Output/Files per rank): consecutive ranges of points give the same patches in
    // the same order; an empty piece is a valid file without points.
    {
      const int                  n = snapshot.points.size();
      Exposed<PointDataOut<dim>> whole, first, second, empty;
      whole.build_patches(snapshot);
      first.build_patches(snapshot, 0, n / 3);
      second.build_patches(snapshot, n / 3, n);
      empty.build_patches(snapshot, n, n);
      mpm_test::check(pieces_make_whole(first, second, whole), "two pieces hold the points of the whole, in order");
      const std::string file = vtu(empty);
      mpm_test::check(file.find("NumberOfPoints=\"0\"") != std::string::npos, "an empty piece is a file without points");
    }

    check_grid(grid);

    // A point that left the grid: marked in the engine's arrays, removed from the handler
    // (which reorders the points of that cell): the same patches, matched by id.
    const int gone = snapshot.points.size() / 2;
    snapshot.points.material[gone] = -1;
    auto it = points.handler.begin();
    std::advance(it, gone);
    points.handler.remove_particle(it);
    Exposed<dealii::Particles::DataOut<dim>> from_handler_after;
    from_handler_after.build_patches(points.handler, layout.names(), layout.interpretations());
    Exposed<PointDataOut<dim>> from_snapshot_after;
    from_snapshot_after.build_patches(snapshot);
    const auto old_patches = by_id(from_handler_after.get_patches());
    const auto new_patches = by_id(from_snapshot_after.get_patches());
    mpm_test::check(static_cast<int>(new_patches.size()) + 1 == snapshot.points.size(), "a point that left the grid is left out");
    bool same = old_patches.size() == new_patches.size();
    for (unsigned int i = 0; same && i < old_patches.size(); ++i)
      same = old_patches[i]->vertices[0] == new_patches[i]->vertices[0] && old_patches[i]->data == new_patches[i]->data;
    mpm_test::check(same, "after a point left the grid: the same points and values as the handler's");
  }
} // namespace

int main(int argc, char **argv)
{
  dealii::Utilities::MPI::MPI_InitFinalize mpi(argc, argv, 1);
  check_dim<2>();
  check_dim<3>();
  return mpm_test::finish("test_output_paths");
}
