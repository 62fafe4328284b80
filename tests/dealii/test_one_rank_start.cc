// On one rank the engine starts before deal.II's grid and ParticleHandler exist
// (simulator.cc): its nodes come from lattice_grid() and its points from
// points_of_bodies(). Both must be what the grid and the handler would have given:
//  - lattice_grid's boundary and friction masks equal BackgroundGrid's (set from the faces'
//    boundary ids) at every node, for boundaries of every type on different faces;
//  - points_of_bodies gives every array of every point and its labels exactly as
//    MaterialPoints::insert + copy_to do (matched by particle id), ordered cell by cell;
//  - an engine on its own lattice nodes steps exactly as one on the grid's vectors: the
//    same points after 40 steps (a block falling onto a no-slip floor beside free-slip
//    walls, with pressure averaging), bit for bit, and the same nodal mass and velocity
//    once nodal_to() has put them into the grid's DoF numbering.
#include <mpm/dealii/engine.h>

#include <deal.II/base/mpi.h>

#include "../core/check.h"
#include "box_scene.h"

#include <cstring>
#include <stdexcept>
#include <string>
#include <vector>

namespace
{
  using namespace mpm;

  // Two bodies (one geostatic, one moving, of other materials) falling in a box whose
  // faces have every type of boundary.
  template <int dim>
  Parameters scene()
  {
    Parameters p = mpm_test::box_domain<dim>(0.08, 0.01);
    p.upper[0]   = 0.12;
    // Every type, on faces of every direction: x min no-slip, x max free-slip, y min friction, ...
    p.boundary = {{BoundaryType::no_slip, BoundaryType::free_slip, BoundaryType::friction,
                   BoundaryType::free_slip, BoundaryType::no_slip, BoundaryType::free}};
    if (dim == 2)
      {
        p.boundary[2] = BoundaryType::no_slip; // the floor
        p.boundary[3] = BoundaryType::friction;
      }
    p.friction_coefficient = 0.5;
    p.gravity[dim - 1] = -9.81;
    BodyParameters body  = mpm_test::box_body<dim>(0.0, 0.04, 2, 2000);
    body.initial_stress  = "geostatic";
    body.k0              = 0.4;
    BodyParameters second = mpm_test::box_body<dim>(0.045, 0.075, 3, 1500);
    second.velocity[0]    = -0.5;
    p.bodies              = {body, second};
    p.body_material       = {0, 1};
    p.materials.resize(2);
    for (auto &m : p.materials)
      {
        m.model                  = MaterialModel::linear_elastic;
        m.elastic.youngs_modulus = 1e6;
        m.elastic.poissons_ratio = 0.3;
      }
    p.materials[1].elastic.youngs_modulus = 4e5;
    p.material_fields.resize(2);
    return p;
  }

  // The lattice's geometry as a view (for its lattice_cell()).
  template <int dim>
  GridView<dim, double> grid_view_of_lattice(const Parameters &p)
  {
    const HostGrid<dim, double> lattice = lattice_geometry<dim>(p);
    GridView<dim, double>       g{};
    g.h = lattice.h;
    for (int d = 0; d < dim; ++d)
      {
        g.origin[d]  = lattice.origin[d];
        g.n_cells[d] = lattice.n_cells[d];
      }
    return g;
  }

  template <int dim>
  void check_masks(const Parameters &p, BackgroundGrid<dim> &grid)
  {
    const HostGrid<dim, double>       lattice = lattice_grid<dim>(p);
    const GridView<dim, double>       g       = grid.view();
    const long                        n       = static_cast<long>(lattice.fixed_components.size());
    long                              differ = 0, constrained = 0;
    std::vector<long>                 count_of_mask(1u << dim, 0);
    for (long l = 0; l < n; ++l)
      {
        const std::uint8_t expected = g.fixed_components[g.node_of_lattice(l)];
        differ += lattice.fixed_components[l] != expected;
        constrained += expected != 0;
        ++count_of_mask[expected];
      }
    mpm_test::check(n == g.n_nodes, "lattice_grid has every node of the grid", n, g.n_nodes);
    mpm_test::check(differ == 0, "lattice_grid's boundary masks equal BackgroundGrid's", differ, 0);
    // Friction masks and coefficients alike; some nodes lie on the frictional face.
    long differ_friction = 0, on_friction_face = 0;
    const bool both = !lattice.friction_faces.empty() && g.friction_faces != nullptr;
    for (long l = 0; both && l < n; ++l)
      {
        const std::uint8_t expected = g.friction_faces[g.node_of_lattice(l)];
        differ_friction += lattice.friction_faces[l] != expected;
        on_friction_face += expected != 0;
      }
    for (int f = 0; f < 2 * dim; ++f)
      differ_friction += lattice.friction_coefficient[f] != g.friction_coefficient[f];
    mpm_test::check(both && differ_friction == 0 && on_friction_face > 0,
                    "lattice_grid's friction masks and coefficients equal BackgroundGrid's", differ_friction, 0);
    // The comparison means something only where the masks are not all alike.
    long kinds = 0;
    for (const long c : count_of_mask)
      kinds += c > 0;
    mpm_test::check(constrained > 0 && kinds >= 3, "the scene has nodes of at least three kinds of mask", kinds, 3);
  }

  template <int dim>
  bool same_points(const HostPoints<dim, double> &a, const HostPoints<dim, double> &b, const std::vector<int> &b_of_a)
  {
    bool same = a.size() == b.size() && static_cast<int>(b_of_a.size()) == a.size();
    auto compare = [&](const auto &x, const auto &y) {
      for (int i = 0; same && i < a.size(); ++i)
        same = std::memcmp(&x[i], &y[b_of_a[i]], sizeof(x[i])) == 0;
    };
    if (same)
      for_each_point_array<dim>(a, b, compare);
    return same;
  }

  template <int dim>
  void check_points(const Parameters &p, const MaterialPoints<dim> &handler_points,
                    const std::vector<GeneratedBody<dim>> &bodies)
  {
    HostPoints<dim, double> from_handler, from_bodies;
    PointLabels<dim>        handler_labels, body_labels;
    handler_points.copy_to(from_handler, nullptr, &handler_labels);
    points_of_bodies(bodies, lattice_geometry<dim>(p), from_bodies, body_labels);

    // Body point of each id, then handler point i is body point index_of_id[id].
    const int        n = from_bodies.size();
    std::vector<int> index_of_id(n, -1), body_index(from_handler.size(), -1);
    bool             labels_same = from_handler.size() == n;
    for (int j = 0; labels_same && j < n; ++j)
      {
        const auto id = body_labels.id[j];
        labels_same   = id < static_cast<decltype(id)>(n) && index_of_id[id] < 0;
        if (labels_same)
          index_of_id[id] = j;
      }
    for (int i = 0; labels_same && i < n; ++i)
      {
        const auto id = handler_labels.id[i];
        labels_same   = id < static_cast<decltype(id)>(n);
        if (!labels_same)
          break;
        body_index[i] = index_of_id[id];
        for (int d = 0; d < dim; ++d)
          labels_same = labels_same && handler_labels.initial_position[d][i] == body_labels.initial_position[d][body_index[i]];
      }
    // Cell by cell (the CPU's scatter depends on it for speed), generation order within a cell.
    const GridView<dim, double> g = grid_view_of_lattice<dim>(p);
    bool                        sorted = true;
    for (int j = 1; j < n; ++j)
      {
        double a[dim], b[dim];
        for (int d = 0; d < dim; ++d)
          {
            a[d] = from_bodies.position[d][j - 1];
            b[d] = from_bodies.position[d][j];
          }
        const int ca = g.lattice_cell(a), cb = g.lattice_cell(b);
        sorted = sorted && (ca < cb || (ca == cb && body_labels.id[j - 1] < body_labels.id[j]));
      }
    mpm_test::check(sorted, "points_of_bodies orders the points by lattice cell, then by id");
    mpm_test::check(from_bodies.size() > 100, "the scene has points", from_bodies.size(), 100);
    mpm_test::check(labels_same, "points_of_bodies' ids and initial positions are the handler's");
    mpm_test::check(labels_same && same_points<dim>(from_handler, from_bodies, body_index),
                    "points_of_bodies' arrays are the handler's, bit for bit");
  }

  // Engine A on its own lattice nodes, engine B on the grid's vectors, same points.
  template <int dim>
  void check_engines(const Parameters &p, BackgroundGrid<dim> &grid_a, BackgroundGrid<dim> &grid_b,
                     const MaterialPoints<dim> &handler_points)
  {
    auto a = make_engine<dim>("cpu", lattice_grid<dim>(p), p.materials, ShapeFunction::gimp);
    auto b = make_engine<dim>("cpu", grid_b, p.materials, ShapeFunction::gimp);
    a->load(handler_points);
    b->load(handler_points);
    StepSettings<dim, double> s;
    s.scheme             = UpdateScheme::musl;
    s.damping            = 0.05;
    s.flip_fraction      = 0.98;
    s.domain_update      = DomainUpdate::det_F;
    s.pressure_averaging = true;
    s.mass_tolerance     = 1e-12;
    for (int d = 0; d < dim; ++d)
      s.gravity[d] = p.gravity[d];
    double max_speed_a = 0, max_speed_b = 0;
    for (int step = 0; step < 40; ++step)
      {
        max_speed_a = a->step(s, 2e-4).max_speed;
        max_speed_b = b->step(s, 2e-4).max_speed;
      }
    PointSnapshot<dim> sa, sb;
    a->snapshot(sa);
    b->snapshot(sb);
    std::vector<int> identity(sa.points.size());
    for (int i = 0; i < sa.points.size(); ++i)
      identity[i] = i;
    mpm_test::check(max_speed_a > 1e-3 && max_speed_a == max_speed_b,
                    "both engines move the points, at the same largest speed", max_speed_a, max_speed_b);
    mpm_test::check(same_points<dim>(sa.points, sb.points, identity),
                    "an engine on its own lattice nodes steps as one on the grid's vectors, bit for bit");

    a->nodal_to(grid_a);
    b->nodal_to(grid_b); // nothing to do: its nodes are the grid's
    long   differ = 0;
    double mass   = 0;
    auto   compare = [&](const auto &x, const auto &y) {
      for (unsigned int i = 0; i < x.locally_owned_size(); ++i)
        {
          const double xi = x.local_element(i), yi = y.local_element(i);
          differ += std::memcmp(&xi, &yi, sizeof(double)) != 0;
        }
    };
    compare(grid_a.mass, grid_b.mass);
    for (int d = 0; d < dim; ++d)
      compare(grid_a.velocity[d], grid_b.velocity[d]);
    for (unsigned int i = 0; i < grid_a.mass.locally_owned_size(); ++i)
      mass += grid_a.mass.local_element(i);
    mpm_test::check(mass > 0, "the nodes carry mass", mass, 0);
    mpm_test::check(differ == 0, "nodal_to puts the lattice-ordered nodes into the grid's DoF numbering", differ, 0);
  }

  template <int dim>
  void check_dim()
  {
    const Parameters                      p      = scene<dim>();
    const std::vector<GeneratedBody<dim>> bodies = generate_bodies<dim>(p);
    BackgroundGrid<dim>                   grid_a(p, MPI_COMM_WORLD), grid_b(p, MPI_COMM_WORLD);
    MaterialPoints<dim>                   points(grid_a, p);
    points.insert(bodies);
    check_masks<dim>(p, grid_a);
    check_points<dim>(p, points, bodies);
    check_engines<dim>(p, grid_a, grid_b, points);
  }
} // namespace

int main(int argc, char **argv)
{
  dealii::Utilities::MPI::MPI_InitFinalize mpi(argc, argv, 1);
  check_dim<2>();
  check_dim<3>();
  {
    // Nodes near the material: a choice that would keep more nodes than an int counts ends with
    // a message naming the parameter (the core throws std::length_error); others pass through.
    std::string message;
    try
      {
        mpm::choose_nodes_near_material(64, []() -> int { throw std::length_error("too many nodes"); });
      }
    catch (const dealii::ExceptionBase &e)
      {
        message = e.what();
      }
    mpm_test::check(message.find("Grid/Active block size = 64") != std::string::npos &&
                      message.find("1 to 64") != std::string::npos,
                    "too many nodes near the material: the error names Grid/Active block size and its range");
    mpm_test::check(mpm::choose_nodes_near_material(4, []() { return 7; }) == 7,
                    "a choice within an int's count passes through");
  }
  return mpm_test::finish("test_one_rank_start");
}
