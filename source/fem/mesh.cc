#include <mpm/fem/mesh.h>

#include <deal.II/base/exceptions.h>
#include <deal.II/grid/grid_generator.h>
#include <deal.II/grid/grid_in.h>
#include <deal.II/grid/grid_tools.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <set>

namespace mpm::fem
{
  using namespace dealii;

  namespace
  {
    [[noreturn]] void fail(const std::string &entry, const std::string &what)
    {
      AssertThrow(false, ExcMessage("Parameter '" + entry + "': " + what));
      throw; // not reached
    }

    // The polygon as a stack of bands along axis a: at the knots t (the vertices' a
    // coordinates) the interval [lo, hi] of the other axis that a cut at t leaves; lo and hi
    // are linear between knots. False if a cut inside a band is not one interval, if two bands
    // disagree at their common knot, or if an interval has no length.
    struct Profile
    {
      std::vector<double> t, lo, hi;
    };

    bool polygon_profile(const std::vector<std::array<double, 2>> &polygon, const int a, Profile &profile)
    {
      const int b = 1 - a;
      std::vector<double> knots;
      for (const auto &v : polygon)
        knots.push_back(v[a]);
      std::sort(knots.begin(), knots.end());
      knots.erase(std::unique(knots.begin(), knots.end()), knots.end());
      const double scale = knots.back() - knots.front();
      if (!(scale > 0))
        return false;
      profile = Profile();
      for (std::size_t k = 0; k + 1 < knots.size(); ++k)
        {
          // The edges a cut in the middle of the band crosses, evaluated at the band's ends.
          const double        mid = 0.5 * (knots[k] + knots[k + 1]);
          std::vector<std::array<double, 2>> crossings; // (value at knots[k], value at knots[k+1])
          for (std::size_t e = 0; e < polygon.size(); ++e)
            {
              const auto &p = polygon[e], &q = polygon[(e + 1) % polygon.size()];
              if ((p[a] - mid) * (q[a] - mid) >= 0)
                continue;
              const auto at = [&](const double t) { return p[b] + (t - p[a]) / (q[a] - p[a]) * (q[b] - p[b]); };
              crossings.push_back({{at(knots[k]), at(knots[k + 1])}});
            }
          if (crossings.size() != 2)
            return false;
          if (crossings[0][0] + crossings[0][1] > crossings[1][0] + crossings[1][1])
            std::swap(crossings[0], crossings[1]);
          const double tolerance = 1e-9 * scale;
          for (int end = 0; end < 2; ++end)
            if (!(crossings[1][end] - crossings[0][end] > tolerance))
              return false; // a band ending in a point: degenerate cells
          if (k == 0)
            {
              profile.t.push_back(knots[0]);
              profile.lo.push_back(crossings[0][0]);
              profile.hi.push_back(crossings[1][0]);
            }
          else if (std::abs(profile.lo.back() - crossings[0][0]) > tolerance ||
                   std::abs(profile.hi.back() - crossings[1][0]) > tolerance)
            return false; // a step in the outline at this knot
          profile.t.push_back(knots[k + 1]);
          profile.lo.push_back(crossings[0][1]);
          profile.hi.push_back(crossings[1][1]);
        }
      return true;
    }

    double interpolate(const std::vector<double> &t, const std::vector<double> &v, const double x)
    {
      std::size_t k = std::upper_bound(t.begin(), t.end(), x) - t.begin();
      k             = std::min(std::max<std::size_t>(k, 1), t.size() - 1);
      const double s = (x - t[k - 1]) / (t[k] - t[k - 1]);
      return v[k - 1] + s * (v[k] - v[k - 1]);
    }

    // The profile's region meshed: a rectangle in (t along a, xi in [0, 1] along the other
    // axis), knots on mesh lines, mapped onto lo(t) + xi (hi(t) - lo(t)).
    void mesh_profile(const Profile &profile, const int a, const double cell_size, Triangulation<2> &mesh)
    {
      std::vector<std::vector<double>> steps(2);
      double widest = 0;
      for (std::size_t k = 0; k < profile.t.size(); ++k)
        widest = std::max(widest, profile.hi[k] - profile.lo[k]);
      const unsigned int across = std::max(1, static_cast<int>(std::ceil(widest / cell_size - 1e-9)));
      steps[1 - a].assign(across, 1.0 / across);
      for (std::size_t k = 0; k + 1 < profile.t.size(); ++k)
        {
          const double       band = profile.t[k + 1] - profile.t[k];
          const unsigned int n    = std::max(1, static_cast<int>(std::ceil(band / cell_size - 1e-9)));
          for (unsigned int i = 0; i < n; ++i)
            steps[a].push_back(band / n);
        }
      Point<2> origin;
      origin[a] = profile.t.front();
      Point<2> end;
      end[a]     = profile.t.back();
      end[1 - a] = 1;
      GridGenerator::subdivided_hyper_rectangle(mesh, steps, origin, end);
      GridTools::transform(
        [&](const Point<2> &p) {
          Point<2>     q  = p;
          const double lo = interpolate(profile.t, profile.lo, p[a]);
          q[1 - a]        = lo + p[1 - a] * (interpolate(profile.t, profile.hi, p[a]) - lo);
          return q;
        },
        mesh);
    }

    template <int dim>
    void read_mesh_file(const std::string &filename, Triangulation<dim> &mesh)
    {
      std::ifstream in(filename);
      if (!in)
        fail("Pre-failure analysis/Mesh file", "cannot open '" + filename + "'.");
      const auto        dot       = filename.rfind('.');
      const std::string extension = dot == std::string::npos ? "" : filename.substr(dot + 1);
      GridIn<dim>       grid_in;
      grid_in.attach_triangulation(mesh);
      try
        {
          if (extension == "msh")
            grid_in.read_msh(in);
          else if (extension == "inp" || extension == "ucd")
            grid_in.read_ucd(in);
          else
            fail("Pre-failure analysis/Mesh file", "'" + filename + "': the extension must be .msh (Gmsh) or "
                                                   ".inp/.ucd (UCD).");
        }
      catch (const ExceptionBase &e)
        {
          std::ostringstream what;
          e.print_info(what);
          fail("Pre-failure analysis/Mesh file", "'" + filename + "' could not be read as a " +
                                                   std::to_string(dim) + "D mesh: " + what.str());
        }
      if (!mesh.all_reference_cells_are_hyper_cube())
        fail("Pre-failure analysis/Mesh file", "'" + filename + "' has cells that are not quadrilaterals (2D) or "
                                               "hexahedra (3D); the FEM stage needs those.");
    }

    template <int dim>
    void mesh_body(const PrefailureScene &scene, Triangulation<dim> &mesh)
    {
      const std::string where = "Material points/Body 1/";
      if (scene.bodies.size() != 1)
        fail("Pre-failure analysis/Mesh", "Mesh = prm bodies meshes one body; the scene has " +
                                            std::to_string(scene.bodies.size()) +
                                            ". For several materials give a mesh file (Mesh = mesh file).");
      const MeshedBody &body = scene.bodies[0];
      const double      h    = scene.settings.cell_size > 0 ? scene.settings.cell_size : scene.default_cell_size;
      if (body.shape == "box")
        {
          std::vector<unsigned int> cells(dim);
          Point<dim>                lo, hi;
          for (int d = 0; d < dim; ++d)
            {
              lo[d]    = body.lower[d];
              hi[d]    = body.upper[d];
              cells[d] = std::max(1, static_cast<int>(std::ceil((hi[d] - lo[d]) / h - 1e-9)));
            }
          GridGenerator::subdivided_hyper_rectangle(mesh, cells, lo, hi);
          return;
        }
      if (body.shape != "polygon")
        fail(where + "Shape", "the FEM stage meshes a box or a polygon, not a " + body.shape +
                                "; give a mesh file (Pre-failure analysis/Mesh = mesh file).");
      Triangulation<2> section;
      mesh_polygon(body.polygon, h, section);
      if constexpr (dim == 2)
        mesh.copy_triangulation(section);
      else
        {
          // Extruded along y between the body's corners: (x, v, s) -> (x, y_max - s, v) keeps the
          // cells' orientation.
          const double       length = body.upper[1] - body.lower[1];
          const unsigned int layers = std::max(1, static_cast<int>(std::ceil(length / h - 1e-9)));
          GridGenerator::extrude_triangulation(section, layers + 1, length, mesh);
          const double y_max = body.upper[1];
          GridTools::transform([y_max](const Point<3> &p) { return Point<3>(p[0], y_max - p[2], p[1]); }, mesh);
        }
    }
  } // namespace

  void mesh_polygon(const std::vector<std::array<double, 2>> &polygon, const double cell_size, Triangulation<2> &mesh)
  {
    Profile profile;
    for (const int a : {0, 1}) // columns first (vertical mesh lines), then rows
      if (polygon_profile(polygon, a, profile))
        {
          mesh_profile(profile, a, cell_size, mesh);
          return;
        }
    fail("Material points/Body 1/Polygon vertices",
         "the FEM stage meshes a polygon that lies between a bottom and a top line over its width, or "
         "between a left and a right line over its height, with no edge of zero length across; this one "
         "does neither. Give a mesh file (Pre-failure analysis/Mesh = mesh file).");
  }

  template <int dim>
  void set_bounding_box_boundary_ids(Triangulation<dim> &mesh)
  {
    const BoundingBox<dim> box   = GridTools::compute_bounding_box(mesh);
    const double           scale = box.side_length(0) + box.side_length(1);
    for (const auto &cell : mesh.active_cell_iterators())
      for (const unsigned int f : cell->face_indices())
        if (cell->face(f)->at_boundary())
          {
            unsigned int id = other_boundary_id;
            for (int d = 0; d < dim && id == other_boundary_id; ++d)
              for (int side = 0; side < 2; ++side)
                {
                  const double plane = side == 0 ? box.lower_bound(d) : box.upper_bound(d);
                  bool         on    = true;
                  for (const unsigned int v : cell->face(f)->vertex_indices())
                    on = on && std::abs(cell->face(f)->vertex(v)[d] - plane) < 1e-10 * scale;
                  if (on)
                    id = 2 * d + side;
                }
            cell->face(f)->set_boundary_id(id);
          }
  }

  template <int dim>
  std::map<types::material_id, FemMaterial> create_mesh(const PrefailureScene &scene,
                                                        parallel::distributed::Triangulation<dim> &triangulation)
  {
    const PrefailureParameters &fem = scene.settings;
    Triangulation<dim>          coarse;
    std::map<types::material_id, FemMaterial> materials;
    const auto material = [&](const unsigned int index, const double density) {
      FemMaterial m;
      m.parameters   = scene.materials[index];
      m.density      = density;
      m.mpm_material = index;
      m.name         = scene.material_names[index];
      return m;
    };
    if (fem.mesh == "mesh file")
      {
        read_mesh_file(fem.mesh_file, coarse);
        std::set<types::material_id> ids;
        for (const auto &cell : coarse.active_cell_iterators())
          ids.insert(cell->material_id());
        for (const types::material_id id : ids)
          {
            const auto named = scene.mesh_materials.find(id);
            if (named == scene.mesh_materials.end())
              fail("Initial state/Materials",
                   "the cells of material_id " + std::to_string(id) + " in '" + fem.mesh_file +
                     "' have no material; name every id as 'id: material name, density' (a mesh file without "
                     "physical groups gives every cell material_id 0).");
            materials[id] = material(named->second.first, named->second.second);
          }
      }
    else
      {
        mesh_body(scene, coarse);
        set_bounding_box_boundary_ids(coarse);
        for (const auto &cell : coarse.active_cell_iterators())
          cell->set_material_id(0);
        materials[0] = material(scene.bodies[0].material, scene.bodies[0].density);
      }
    for (const auto &[id, m] : materials)
      if (m.parameters.model == MaterialModel::user_defined)
        fail("Materials/Material " + m.name + "/Model",
             "the FEM stage needs the consistent tangent of the built-in models (linear elastic, Drucker-Prager, "
             "Mohr-Coulomb); a model defined outside the library gives none.");
      else if (m.parameters.field_parameter != FieldParameter::none)
        fail("Materials/Material " + m.name + "/Random field",
             "the FEM stage takes uniform materials; a random field is not carried into it.");
    triangulation.copy_triangulation(coarse);
    // Periodic pairs (checked in the parameters: ids 2d, 2d + 1 both periodic) are tied on
    // the coarse mesh, before refinement, as p4est needs.
    for (int d = 0; d < dim; ++d)
      if (fem.boundary_conditions.count(2 * d) && fem.boundary_conditions.at(2 * d) == BoundaryCondition::periodic)
        {
          std::vector<GridTools::PeriodicFacePair<typename parallel::distributed::Triangulation<dim>::cell_iterator>> pairs;
          GridTools::collect_periodic_faces(triangulation, 2 * d, 2 * d + 1, d, pairs);
          if (pairs.empty())
            fail("Pre-failure analysis/Boundary conditions",
                 "boundary ids " + std::to_string(2 * d) + " and " + std::to_string(2 * d + 1) +
                   " are periodic, but the mesh has no faces of those ids to pair.");
          triangulation.add_periodicity(pairs);
        }
    triangulation.refine_global(fem.global_refinements);
    return materials;
  }

  template void set_bounding_box_boundary_ids(Triangulation<2> &);
  template void set_bounding_box_boundary_ids(Triangulation<3> &);
  template std::map<types::material_id, FemMaterial> create_mesh(const PrefailureScene &,
                                                                 parallel::distributed::Triangulation<2> &);
  template std::map<types::material_id, FemMaterial> create_mesh(const PrefailureScene &,
                                                                 parallel::distributed::Triangulation<3> &);
} // namespace mpm::fem
