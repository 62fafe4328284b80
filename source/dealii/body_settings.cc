#include <mpm/dealii/body_settings.h>
#include <mpm/dealii/parameter_error.h>
#include <mpm/dealii/prm_reading.h>

#include <deal.II/base/utilities.h>

#include <algorithm>
#include <iomanip>
#include <limits>
#include <sstream>

namespace mpm
{
  using dealii::ParameterHandler;
  namespace Patterns = dealii::Patterns;
  using namespace prm_reading;

  namespace
  {
    // The first two edges of a closed polygon that meet other than at the vertex they share
    // (edge k runs from vertex k to vertex k + 1, the last back to vertex 0), or {-1, -1}: the
    // points fill a polygon by the even-odd rule, so a polygon that crosses itself (vertices in
    // the wrong order) leaves holes where the two sides overlap.
    std::pair<int, int> crossing_edges(const std::vector<std::array<double, 2>> &v)
    {
      const int  n      = static_cast<int>(v.size());
      const auto orient = [](const std::array<double, 2> &a, const std::array<double, 2> &b,
                             const std::array<double, 2> &c) {
        const double cross = (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]);
        return (cross > 0) - (cross < 0);
      };
      const auto on_segment = [](const std::array<double, 2> &a, const std::array<double, 2> &b,
                                 const std::array<double, 2> &c) { // c on the line ab: within its box?
        return std::min(a[0], b[0]) <= c[0] && c[0] <= std::max(a[0], b[0]) && std::min(a[1], b[1]) <= c[1] &&
               c[1] <= std::max(a[1], b[1]);
      };
      for (int k = 0; k < n; ++k)
        for (int m = k + 1; m < n; ++m)
          {
            const auto &a = v[k], &b = v[(k + 1) % n], &c = v[m], &d = v[(m + 1) % n];
            const int   o1 = orient(a, b, c), o2 = orient(a, b, d), o3 = orient(c, d, a), o4 = orient(c, d, b);
            const bool  adjacent = m == k + 1 || (k == 0 && m == n - 1);
            if (adjacent)
              {
                // Neighbours share a vertex; they overlap only if they fold back along one line.
                const auto &shared = m == k + 1 ? b : a, &far_k = m == k + 1 ? a : b, &far_m = m == k + 1 ? d : c;
                if (orient(far_k, shared, far_m) == 0 &&
                    (far_m[0] - shared[0]) * (far_k[0] - shared[0]) + (far_m[1] - shared[1]) * (far_k[1] - shared[1]) > 0)
                  return {k, m};
                continue;
              }
            if ((o1 != o2 && o3 != o4) || (o1 == 0 && on_segment(a, b, c)) || (o2 == 0 && on_segment(a, b, d)) ||
                (o3 == 0 && on_segment(c, d, a)) || (o4 == 0 && on_segment(c, d, b)))
              return {k, m};
          }
      return {-1, -1};
    }
  } // namespace

  void BodySettings::declare(ParameterHandler &prm, const unsigned int dim, const unsigned int n_bodies,
                             const std::vector<std::string> &material_names)
  {
    prm.enter_subsection("Material points");
    for (unsigned int b = 1; b <= n_bodies; ++b)
      {
        prm.enter_subsection("Body " + std::to_string(b));
        prm.declare_entry("Shape", "box", Patterns::Selection("box|polygon|cylinder"),
                          "box: the points fill [Lower corner, Upper corner]. polygon: the points fill the polygon "
                          "given by 'Polygon vertices' in the (x, vertical) plane; in 3D it is extruded along y "
                          "between the y coordinates of Lower and Upper corner. cylinder (3D only): the points of "
                          "the box [Lower corner, Upper corner] within 'Radius' of the vertical line through "
                          "'Cylinder axis' (a column, or the quarter of one cut by the box).");
        prm.declare_entry("Lower corner", zeros(dim), point_pattern(dim), "Lower corner of the box (m).");
        prm.declare_entry("Upper corner", ones(dim), point_pattern(dim), "Upper corner of the box (m).");
        prm.declare_entry("Polygon vertices", "",
                          Patterns::List(Patterns::List(Patterns::Double(), 2, 2, ","), 0,
                                         Patterns::List::max_int_value, ";"),
                          "Vertices 'x1, v1; x2, v2; ...' of the polygon (at least 3), v the vertical "
                          "coordinate (y in 2D, z in 3D).");
        prm.declare_entry("Cylinder axis", "0, 0", Patterns::List(Patterns::Double(), 2, 2, ","),
                          "Shape = cylinder: the horizontal coordinates 'x, y' of the cylinder's vertical axis (m).");
        prm.declare_entry("Radius", "0", Patterns::Double(0), "Shape = cylinder: its radius (m), > 0.");
        prm.declare_entry("Points per cell direction", "2", Patterns::Integer(1, 10),
                          "Material points per cell along each direction (2 gives 2x2 in 2D, 2x2x2 in 3D).");
        prm.declare_entry("Density", "1000", Patterns::Double(0), "Mass density (kg/m^3, > 0).");
        prm.declare_entry("Initial velocity", zeros(dim), point_pattern(dim), "Initial velocity (m/s).");
        prm.declare_entry("Material", material_names.front(), Patterns::Anything(),
                          "Name of this body's material, one of the names in Materials/Names.");
        prm.declare_entry("Initial stress", "none", Patterns::Selection("none|geostatic"),
                          "none: stress free. geostatic: vertical stress -|g| times the weight per unit area of "
                          "the material of all bodies above the point (sum of density x thickness; stacked "
                          "bodies load the ones below), horizontal stresses K0 of this body times it.");
        prm.declare_entry("K0", "0.5", Patterns::Double(0), "Lateral earth pressure coefficient for geostatic.");
        prm.leave_subsection();
      }
    prm.leave_subsection();
  }

  void BodySettings::parse(ParameterHandler &prm, const unsigned int dim, const unsigned int n_bodies,
                           const std::vector<std::string> &material_names, const std::vector<double> &lower,
                           const std::vector<double> &upper)
  {
    prm.enter_subsection("Material points");
    bodies_lo.assign(dim, std::numeric_limits<double>::max());
    bodies_hi.assign(dim, std::numeric_limits<double>::lowest());
    for (unsigned int b = 1; b <= n_bodies; ++b)
      {
        const std::string where = "Material points/Body " + std::to_string(b) + "/";
        prm.enter_subsection("Body " + std::to_string(b));
        BodyParameters body;
        body.shape = prm.get("Shape");
        body.lower = get_point(prm, "Lower corner", where);
        body.upper = get_point(prm, "Upper corner", where);
        for (const std::string &vertex :
             dealii::Utilities::split_string_list(prm.get("Polygon vertices"), ';'))
          {
            const auto xy = to_doubles(where + "Polygon vertices", vertex);
            body.polygon.push_back({{xy[0], xy[1]}});
          }
        {
          const auto axis = to_doubles(where + "Cylinder axis", prm.get("Cylinder axis"));
          body.axis   = {{axis[0], axis[1]}};
          body.radius = prm.get_double("Radius");
        }
        body.points_per_direction = prm.get_integer("Points per cell direction");
        body.density              = prm.get_double("Density");
        body.velocity             = get_point(prm, "Initial velocity", where);
        body.material             = prm.get("Material");
        body.initial_stress       = prm.get("Initial stress");
        body.k0                   = prm.get_double("K0");
        prm.leave_subsection();

        if (!(body.density > 0))
          parameter_error(where + "Density", "must be > 0.");
        unsigned int material_index = material_names.size();
        for (unsigned int m = 0; m < material_names.size(); ++m)
          if (material_names[m] == body.material)
            material_index = m;
        if (material_index == material_names.size())
          parameter_error(where + "Material", "'" + body.material + "' is not one of Materials/Names (allowed: " +
                                     join(material_names) + ").");
        if (body.shape == "cylinder" && dim != 3)
          parameter_error(where + "Shape", "a cylinder (a vertical column) needs Dimension = 3; in 2D use box or polygon.");
        if (body.shape == "cylinder" && !(body.radius > 0))
          parameter_error(where + "Radius", "a cylinder needs a radius > 0.");
        if (body.shape == "polygon" && body.polygon.size() < 3)
          parameter_error(where + "Polygon vertices", "a polygon needs at least 3 vertices, got " +
                                             std::to_string(body.polygon.size()) + ".");
        if (body.shape == "polygon")
          {
            const auto [k, m] = crossing_edges(body.polygon);
            const int n = static_cast<int>(body.polygon.size());
            const auto edge = [n](const int e) {
              return "from vertex " + std::to_string(e + 1) + " to vertex " + std::to_string((e + 1) % n + 1);
            };
            if (k >= 0)
              parameter_error(where + "Polygon vertices",
                   "the polygon crosses itself: its edge " + edge(k) + " meets the edge " + edge(m) +
                     ". Give the vertices in order around the boundary (either direction), so that no two edges "
                     "cross or overlap.");
          }
        // The body must lie inside the grid: a point outside could never be used.
        std::vector<double> lo = body.lower, hi = body.upper;
        if (body.shape == "polygon")
          {
            lo[0] = hi[0] = body.polygon[0][0];
            lo[dim - 1] = hi[dim - 1] = body.polygon[0][1];
            for (const auto &v : body.polygon)
              {
                lo[0]       = std::min(lo[0], v[0]);
                hi[0]       = std::max(hi[0], v[0]);
                lo[dim - 1] = std::min(lo[dim - 1], v[1]);
                hi[dim - 1] = std::max(hi[dim - 1], v[1]);
              }
          }
        // The entry at fault: a polygon's vertices, or the box corner on the side that is wrong.
        const auto entry = [&body](const bool upper_side) {
          return body.shape == "polygon" ? std::string("Polygon vertices") :
                                           std::string(upper_side ? "Upper corner" : "Lower corner");
        };
        const auto number = [](const double x) { // 0.6, not 0.59999999999999998
          std::ostringstream out;
          out << std::setprecision(12) << x;
          return out.str();
        };
        for (unsigned int d = 0; d < dim; ++d)
          {
            if (!(hi[d] > lo[d]))
              parameter_error(where + entry(true), std::string(hi[d] < lo[d] ? "the upper corner lies below the lower one in " :
                                                                      "the body has no extent in ") +
                                          axis_names[d] + " (" + number(lo[d]) + " to " + number(hi[d]) + ").");
            if (lo[d] < lower[d] - 1e-12 || hi[d] > upper[d] + 1e-12)
              parameter_error(where + entry(hi[d] > upper[d] + 1e-12),
                   std::string("the body reaches outside the grid in ") + axis_names[d] + " ([" + number(lo[d]) +
                     ", " + number(hi[d]) + "] is not inside [" + number(lower[d]) + ", " + number(upper[d]) +
                     "]).");
          }
        if (body.shape == "cylinder")
          for (unsigned int d = 0; d < 2; ++d)
            {
              lo[d] = body.axis[d] - body.radius;
              hi[d] = body.axis[d] + body.radius;
            }
        for (unsigned int d = 0; d < dim; ++d)
          {
            bodies_lo[d] = std::min(bodies_lo[d], lo[d]);
            bodies_hi[d] = std::max(bodies_hi[d], hi[d]);
          }
        bodies.push_back(body);
        body_material.push_back(material_index);
      }
    prm.leave_subsection();
  }
} // namespace mpm
