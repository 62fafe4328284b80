#include <mpm/core/point_generation.h>
#include <mpm/dealii/material_points.h>
#include <mpm/fields/gaussian_random_field.h>

#include <deal.II/base/mpi.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <memory>
#include <sstream>

namespace mpm
{
  std::string state_variable_count_mismatch(const int given, const std::vector<std::string> &names)
  {
    std::string list;
    for (const std::string &name : names)
      list += (list.empty() ? "" : ", ") + name;
    return "The material points carry " + std::to_string(given) + " state variable(s), but the run's material " +
           "models declare " + std::to_string(names.size()) + (names.empty() ? "" : " (" + list + ")") +
           ": every point needs a value of each (QuadraturePointState::state_variables in a hand-over).";
  }

  template <int dim>
  MaterialPoints<dim>::MaterialPoints(BackgroundGrid<dim> &grid, const Parameters &parameters)
    : handler(grid.triangulation, grid.mapping,
              PropertyLayout<dim>(parameters.point_fields, parameters.state_variable_names()).n_properties())
    , state_variable_names(parameters.state_variable_names())
    , layout(parameters.point_fields, state_variable_names)
    , grid(grid)
  {
    // The cell weights of the load balance: cell_partition_weight (background_grid.h).
    const double point_weight = parameters.parallel.point_weight;
    this->point_weight        = (cell_partition_weight(1, point_weight) - cell_partition_weight(0, point_weight)) / 16.;
    empty_cells_weigh         = empty_cells_cost(parameters);
    using CellStatus                 = typename dealii::Triangulation<dim>::CellStatus;
    const unsigned int lattice_cells = grid.lattice_cells_per_grid_cell;
    weight_connection                = grid.triangulation.signals.weight.connect(
      [this, point_weight, lattice_cells](const typename dealii::Triangulation<dim>::cell_iterator &cell,
                                          const CellStatus status) -> unsigned int {
        // Refined near the material (refine_near_points): each child of a refined cell (deal.II
        // hands over the parent, still active) gets its share of the parent's points and cells.
        // Never coarsened.
        if (status == dealii::Triangulation<dim>::CELL_REFINE || status == dealii::Triangulation<dim>::CELL_INVALID)
          {
            const unsigned int children = dealii::GeometryInfo<dim>::max_children_per_cell;
            const double points = cell->is_active() ? double(handler.n_particles_in_cell(cell)) / children : 0.0;
            const unsigned int covered = cell->level() + 1 == this->grid.finest_level ?
                                           lattice_cells :
                                           lattice_cells * dealii::Utilities::pow(2, dim * (this->grid.finest_level - cell->level() - 1));
            return cell_partition_weight(points, point_weight, covered, empty_cells_weigh);
          }
        return cell_partition_weight(handler.n_particles_in_cell(cell), point_weight, lattice_cells,
                                     empty_cells_weigh);
      });
  }

  namespace
  {
    // Length of the vertical line through horizontal coordinate x that lies inside the
    // polygon above height z (the polygon's edges cut the line into inside intervals).
    double polygon_thickness_above(const std::vector<std::array<double, 2>> &polygon, const double x,
                                   const double z)
    {
      std::vector<double> cuts;
      for (size_t i = 0, j = polygon.size() - 1; i < polygon.size(); j = i++)
        {
          const auto &a = polygon[j], &b = polygon[i];
          // Half-open in x: a vertex shared by two edges is counted once; vertical edges never.
          if ((a[0] <= x && x < b[0]) || (b[0] <= x && x < a[0]))
            cuts.push_back(a[1] + (x - a[0]) / (b[0] - a[0]) * (b[1] - a[1]));
        }
      std::sort(cuts.begin(), cuts.end());
      double thickness = 0;
      for (size_t k = 0; k + 1 < cuts.size(); k += 2)
        thickness += std::max(0.0, cuts[k + 1] - std::max(cuts[k], z));
      return thickness;
    }

    // Weight per unit area of the material of all bodies above point x, for the geostatic
    // initial stress: the sum over the bodies of density times the body's thickness above x
    // on the vertical through it. Stacked bodies (layers) load the ones below them.
    template <int dim>
    double overburden(const Parameters &parameters, const double *x)
    {
      double weight = 0;
      for (const BodyParameters &body : parameters.bodies)
        {
          // A polygon gives x through its vertices; its other horizontal extent (y in 3D),
          // like a box's, through the corners.
          bool      covers = true;
          const int first  = body.shape == "polygon" ? 1 : 0;
          for (int d = first; d < dim - 1; ++d)
            covers = covers && body.lower[d] <= x[d] && x[d] <= body.upper[d];
          if (body.shape == "cylinder")
            covers = covers && std::hypot(x[0] - body.axis[0], x[1] - body.axis[1]) <= body.radius;
          if (!covers)
            continue;
          const double thickness =
            body.shape == "polygon" ?
              polygon_thickness_above(body.polygon, x[0], x[dim - 1]) :
              std::max(0.0, body.upper[dim - 1] - std::max(body.lower[dim - 1], x[dim - 1]));
          weight += body.density * thickness;
        }
      return weight;
    }

    // A random field whose standard deviation is large against its mean puts many points
    // below zero; raised to the floor, they shift the field's mean and distribution.
    void check_clipped_fraction(const Parameters &p, const unsigned int m, const long n_clipped, const long n)
    {
      const double fraction = n > 0 ? double(n_clipped) / n : 0;
      if (fraction <= p.material_field_max_clipped[m])
        return;
      const RandomFieldParameters &rf    = p.material_fields[m];
      const bool                   angle = p.materials[m].field_parameter == FieldParameter::friction_angle;
      const double                 unit  = angle ? 180 / M_PI : 1; // prm units: degrees, Pa
      const std::string            where = "Material " + p.material_names[m] + "/Random field/";
      std::ostringstream           what;
      what.precision(3);
      what << 100 * fraction << "% of the material's points (" << n_clipped << " of " << n
           << ") drew a value below 1e-3 of the mean (" << rf.mean * unit << (angle ? " deg" : " Pa")
           << ") and would be raised to that floor, more than Maximum clipped fraction = "
           << 100 * p.material_field_max_clipped[m] << "%: the field's mean and spread would not be those given. "
           << "Standard deviation " << rf.standard_deviation * unit << " is " << rf.standard_deviation / rf.mean
           << " times the mean; below about mean / 2.33 (" << rf.mean * unit / 2.33
           << ") at most 1% of a Gaussian lies below zero. Reduce the standard deviation, or raise Maximum "
              "clipped fraction (0..1) if the floor is meant.";
      AssertThrow(false, dealii::ExcMessage("Parameter '" + where + "Standard deviation': " + what.str()));
    }

    // Whether x lies inside the body, by more than `margin` (points on a shared face are in
    // neither of two bodies that touch).
    template <int dim>
    bool inside_body(const BodyParameters &body, const double *x, const double margin)
    {
      const int first = body.shape == "polygon" ? 1 : 0; // a polygon's x and vertical come from its vertices
      for (int d = first; d < (body.shape == "polygon" ? dim - 1 : dim); ++d)
        if (!(x[d] > body.lower[d] + margin && x[d] < body.upper[d] - margin))
          return false;
      if (body.shape == "cylinder")
        return std::hypot(x[0] - body.axis[0], x[1] - body.axis[1]) < body.radius - margin;
      if (body.shape != "polygon")
        return true;
      std::vector<double> px, pv;
      for (const auto &v : body.polygon)
        {
          px.push_back(v[0]);
          pv.push_back(v[1]);
        }
      if (!inside_polygon(px, pv, x[0], x[dim - 1]))
        return false;
      for (std::size_t i = 0, j = px.size() - 1; i < px.size(); j = i++) // not on an edge
        {
          const double ex = px[i] - px[j], ev = pv[i] - pv[j];
          const double t  = std::clamp(((x[0] - px[j]) * ex + (x[dim - 1] - pv[j]) * ev) /
                                        std::max(ex * ex + ev * ev, 1e-300), 0.0, 1.0);
          if (std::hypot(x[0] - px[j] - t * ex, x[dim - 1] - pv[j] - t * ev) <= margin)
            return false;
        }
      return true;
    }

    // Bodies must not overlap: the points of both would be kept, the overlap's mass counted
    // twice (and its geostatic weight). Refused naming both bodies.
    template <int dim>
    void check_no_overlap(const Parameters &p, const std::vector<GeneratedBody<dim>> &bodies)
    {
      const double margin = 1e-9 * p.cell_size;
      for (unsigned int b = 0; b < bodies.size(); ++b)
        for (unsigned int other = 0; other < bodies.size(); ++other)
          {
            if (other == b)
              continue;
            const HostPoints<dim, double> &points = bodies[b].points;
            long                           n      = 0;
            double                         mass   = 0;
            int                            first  = -1;
            for (int i = 0; i < points.size(); ++i)
              {
                double x[dim];
                for (int d = 0; d < dim; ++d)
                  x[d] = points.position[d][i];
                if (inside_body<dim>(p.bodies[other], x, margin))
                  {
                    n += 1;
                    mass += points.mass[i];
                    first = first < 0 ? i : first;
                  }
              }
            if (n == 0)
              continue;
            std::ostringstream what;
            what.precision(4);
            what << "Parameter 'Material points/Body " << b + 1 << "': the body overlaps Material points/Body "
                 << other + 1 << ": " << n << " of its " << points.size() << " points (" << mass
                 << (dim == 2 ? " kg per m of thickness" : " kg") << ") lie inside Body " << other + 1
                 << ", the first at (";
            for (int d = 0; d < dim; ++d)
              what << (d ? ", " : "") << points.position[d][first];
            what << "). Overlapping bodies are refused: the points of both would be kept and the overlap's "
                    "mass counted twice. Give each region to one body only (a polygon can follow the other "
                    "body's outline; bodies may touch).";
            AssertThrow(false, dealii::ExcMessage(what.str()));
          }
    }
  } // namespace

  template <int dim>
  std::vector<GeneratedBody<dim>> generate_bodies(const Parameters &parameters)
  {
    const HostGrid<dim, double> lattice = lattice_geometry<dim>(parameters);

    // Random fields of material parameters, one per material that has one, over the grid.
    std::map<unsigned int, std::unique_ptr<GaussianRandomField<dim>>> fields;
    for (unsigned int m = 0; m < parameters.materials.size(); ++m)
      if (parameters.materials[m].field_parameter != FieldParameter::none)
        {
          const RandomFieldParameters &rf = parameters.material_fields[m];
          std::array<double, dim>      lo, hi;
          double                       spacing = lattice.h;
          for (int d = 0; d < dim; ++d)
            {
              lo[d]   = lattice.origin[d];
              hi[d]   = lattice.origin[d] + lattice.n_cells[d] * lattice.h;
              spacing = std::min(spacing, rf.correlation_length[d] / 4);
            }
          fields[m] = std::make_unique<GaussianRandomField<dim>>(rf, lo, hi, spacing);
        }

    std::vector<GeneratedBody<dim>> bodies(parameters.bodies.size());
    std::map<unsigned int, std::pair<long, long>> clipped; // material -> (points raised to the floor, points)
    for (unsigned int b = 0; b < parameters.bodies.size(); ++b)
      {
        bodies[b].points.fields    = parameters.point_fields;
        const BodyParameters &body = parameters.bodies[b];
        BodyDescription<dim, double> description;
        description.points_per_direction = body.points_per_direction;
        description.density              = body.density;
        description.material             = parameters.body_material[b];
        for (int d = 0; d < dim; ++d)
          description.velocity[d] = body.velocity[d];

        double lower[dim], upper[dim];
        for (int d = 0; d < dim; ++d)
          {
            lower[d] = body.lower[d];
            upper[d] = body.upper[d];
          }
        std::vector<double> px, pv;
        if (body.shape == "polygon")
          {
            for (const auto &v : body.polygon)
              {
                px.push_back(v[0]);
                pv.push_back(v[1]);
              }
            lower[0] = *std::min_element(px.begin(), px.end());
            upper[0] = *std::max_element(px.begin(), px.end());
            lower[dim - 1] = *std::min_element(pv.begin(), pv.end());
            upper[dim - 1] = *std::max_element(pv.begin(), pv.end());
          }
        HostPoints<dim, double> &points = bodies[b].points;
        const std::vector<double> initial_state = parameters.initial_state_variables(parameters.body_material[b]);
        points.set_n_state_variables(static_cast<int>(initial_state.size()));
        add_points(points, lattice, lower, upper, description, [&](const double *x) {
          if (body.shape == "cylinder")
            return std::hypot(x[0] - body.axis[0], x[1] - body.axis[1]) <= body.radius;
          return body.shape != "polygon" || inside_polygon(px, pv, x[0], x[dim - 1]);
        });

        const double g_vertical = std::abs(parameters.gravity[dim - 1]);
        const auto   field      = fields.find(parameters.body_material[b]);
        for (int i = 0; i < points.size(); ++i)
          {
            double x[dim];
            for (int d = 0; d < dim; ++d)
              x[d] = points.position[d][i];
            for (int c = 0; c < n_voigt; ++c)
              points.stress[c][i] = 0;
            if (body.initial_stress == "geostatic")
              {
                const double sv     = -g_vertical * overburden<dim>(parameters, x);
                points.stress[0][i] = body.k0 * sv;
                points.stress[1][i] = dim == 2 ? sv : body.k0 * sv;
                points.stress[2][i] = dim == 2 ? body.k0 * sv : sv;
              }
            for (std::size_t k = 0; k < initial_state.size(); ++k)
              points.state_variables[k][i] = initial_state[k];
            points.material_field[i] = 0;
            if (field != fields.end())
              {
                std::array<double, dim> xa;
                for (int d = 0; d < dim; ++d)
                  xa[d] = x[d];
                // A Gaussian field can go below zero: cohesion and modulus are kept positive.
                const double v           = field->second->value(xa);
                const double floor       = 1e-3 * std::abs(parameters.material_fields[field->first].mean);
                points.material_field[i] = std::max(v, floor);
                clipped[field->first].first += v < floor;
                clipped[field->first].second += 1;
              }
          }
      }
    // Every rank generates every body: the checks find the same on every rank.
    for (const auto &[m, count] : clipped)
      check_clipped_fraction(parameters, m, count.first, count.second);
    check_no_overlap<dim>(parameters, bodies);
    return bodies;
  }

  template <int dim>
  void MaterialPoints<dim>::insert(const std::vector<GeneratedBody<dim>> &bodies)
  {
    dealii::types::particle_index id = 0;
    std::vector<double>           properties(layout.n_properties());
    for (const GeneratedBody<dim> &body : bodies)
      {
        const HostPoints<dim, double> &points = body.points;
        AssertThrow(points.n_state_variables() == static_cast<int>(state_variable_names.size()),
                    dealii::ExcMessage(state_variable_count_mismatch(points.n_state_variables(),
                                                                     state_variable_names)));
        // One allocation of the property pool for all points (an upper bound on one rank's).
        handler.reserve(handler.n_locally_owned_particles() + points.size());
        for (int i = 0; i < points.size(); ++i, ++id)
          {
            double x[dim];
            for (int d = 0; d < dim; ++d)
              x[d] = points.position[d][i];
            const auto cell = grid.owned_cell(grid.lattice_cell_of(x));
            if (cell == grid.triangulation.end())
              continue; // another rank owns this point's cell

            // F, strain and plastic strain as given (I and zeros for the prm's bodies; a
            // state handed over keeps its own).
            layout.write(points, i, properties.data());
            for (int d = 0; d < dim; ++d)
              properties[layout.offset(PointField::initial_position) + d] = x[d];

            dealii::Point<dim> location;
            for (int d = 0; d < dim; ++d)
              location[d] = x[d];
            const dealii::Point<dim> reference = grid.mapping.transform_real_to_unit_cell(cell, location);
            // Straight into the handler's pool, without a Particle and a second copy of the properties.
            handler.insert_particle(location, reference, id, cell,
                                    dealii::ArrayView<const double>(properties.data(), properties.size()));
          }
      }
    n_generated = id;
    handler.update_cached_numbers();
  }

  template <int dim>
  void points_of_bodies(const std::vector<GeneratedBody<dim>> &bodies, const HostGrid<dim, double> &lattice,
                        HostPoints<dim, double> &p, PointLabels<dim> &labels)
  {
    // Generation index -> (body, index in the body), and each point's lattice cell.
    std::vector<std::pair<int, int>> source;
    std::vector<long>                cell;
    long                             n_cells = 1;
    for (int d = 0; d < dim; ++d)
      n_cells *= lattice.n_cells[d];
    for (unsigned int b = 0; b < bodies.size(); ++b)
      for (int k = 0; k < bodies[b].points.size(); ++k)
        {
          source.emplace_back(b, k);
          long c = 0;
          for (int d = dim - 1; d >= 0; --d)
            {
              long i = static_cast<long>(std::floor((bodies[b].points.position[d][k] - lattice.origin[d]) / lattice.h));
              i      = std::min<long>(std::max<long>(i, 0), lattice.n_cells[d] - 1);
              c      = c * lattice.n_cells[d] + i;
            }
          cell.push_back(c);
        }
    // Cell by cell, as in the handler (the points of a cell write the same nodes: the CPU's
    // scatter runs 12% slower on P2-like scenes in generation order), generation order within
    // a cell: a stable counting sort.
    const int         n = static_cast<int>(source.size());
    std::vector<int>  start(n_cells + 1, 0), order(n);
    for (const long c : cell)
      ++start[c + 1];
    for (long c = 0; c < n_cells; ++c)
      start[c + 1] += start[c];
    for (int g = 0; g < n; ++g)
      order[start[cell[g]]++] = g;

    p.resize(0);
    if (!bodies.empty())
      p.fields = bodies[0].points.fields;
    p.set_n_state_variables(bodies.empty() ? 0 : bodies[0].points.n_state_variables());
    p.resize(n);
    labels.id.resize(n);
    for (int d = 0; d < dim; ++d)
      labels.initial_position[d].resize(n);
    for (int i = 0; i < n; ++i)
      {
        const int                      g = order[i];
        const HostPoints<dim, double> &b = bodies[source[g].first].points;
        const int                      k = source[g].second;
        labels.id[i] = g; // the generation index, as insert() numbers the particles
        for (int d = 0; d < dim; ++d)
          labels.initial_position[d][i] = b.position[d][k];
        // Every field, as insert() and copy_to() carry them.
        for_each_point_array<dim>(p, b, [&](auto &to, const auto &from) { to[i] = from[k]; });
      }
  }

  template <int dim>
  void MaterialPoints<dim>::copy_to(HostPoints<dim, double> &p, std::vector<long> *home_cells,
                                    PointLabels<dim> *labels) const
  {
    const unsigned int n = handler.n_locally_owned_particles();
    const int          n_state = static_cast<int>(state_variable_names.size());
    p.resize(0);
    p.fields = layout.carried;
    p.set_n_state_variables(n_state);
    p.resize(n);
    if (home_cells)
      home_cells->resize(n);
    if (labels)
      {
        labels->state_variable_names = state_variable_names;
        labels->id.resize(n);
        for (int d = 0; d < dim; ++d)
          labels->initial_position[d].resize(n);
      }
    int i = 0;
    for (const auto &particle : handler)
      {
        if (labels)
          {
            labels->id[i] = particle.get_id();
            for (int d = 0; d < dim; ++d)
              labels->initial_position[d][i] =
                particle.get_properties()[layout.offset(PointField::initial_position) + d];
          }
        const auto x    = particle.get_location();
        const auto prop = particle.get_properties();
        if (home_cells)
          (*home_cells)[i] = grid.lattice_cell_in(particle.get_surrounding_cell(), &x[0]);
        for (int d = 0; d < dim; ++d)
          p.position[d][i] = x[d];
        layout.read(prop.data(), p, i);
        ++i;
      }
  }

  // The inverse of copy_to's property reads: where copy_to reads prop[k] into an array,
  // this writes that array back to values[k]; initial_position comes from the labels.
  template <int dim>
  PointSnapshot<dim> PointSnapshot<dim>::selected(const std::function<bool(int)> &keep) const
  {
    std::vector<int> kept;
    for (int i = 0; i < points.size(); ++i)
      if (keep(i))
        kept.push_back(i);
    PointSnapshot<dim> part;
    part.points.fields = points.fields;
    part.points.set_n_state_variables(points.n_state_variables());
    part.points.resize(static_cast<int>(kept.size()));
    for_each_point_array<dim>(part.points, points, [&](auto &to, const auto &from) {
      for (std::size_t k = 0; k < kept.size(); ++k)
        to[k] = from[kept[k]];
    });
    auto labels                  = std::make_shared<PointLabels<dim>>();
    labels->state_variable_names = this->labels->state_variable_names;
    for (const int i : kept)
      {
        labels->id.push_back(this->labels->id[i]);
        for (int d = 0; d < dim; ++d)
          labels->initial_position[d].push_back(this->labels->initial_position[d][i]);
      }
    part.labels = std::move(labels);
    return part;
  }

  template <int dim>
  void PointSnapshot<dim>::properties(const PropertyLayout<dim> &layout, const int i, double *values) const
  {
    layout.write(points, i, values);
    for (int d = 0; d < dim; ++d)
      values[layout.offset(PointField::initial_position) + d] = labels->initial_position[d][i];
  }

  template <int dim>
  void MaterialPoints<dim>::replace(const PointSnapshot<dim> &all)
  {
    AssertThrow(all.points.n_state_variables() == static_cast<int>(state_variable_names.size()),
                dealii::ExcMessage(state_variable_count_mismatch(all.points.n_state_variables(), state_variable_names)));
    handler.clear_particles();
    std::vector<double> properties(layout.n_properties());
    for (int i = 0; i < all.points.size(); ++i)
      {
        if (all.points.material[i] < 0)
          continue;
        double             x[dim];
        dealii::Point<dim> location;
        for (int d = 0; d < dim; ++d)
          location[d] = x[d] = all.points.position[d][i];
        const auto cell = grid.owned_cell(grid.lattice_cell_of(x));
        if (cell == grid.triangulation.end())
          continue; // another rank owns this point's cell
        all.properties(layout, i, properties.data());
        handler.insert_particle(location, grid.mapping.transform_real_to_unit_cell(cell, location),
                                all.labels->id[i], cell,
                                dealii::ArrayView<const double>(properties.data(), properties.size()));
      }
    handler.update_cached_numbers();
  }

  template <int dim>
  unsigned int MaterialPoints<dim>::copy_from(const HostPoints<dim, double> &p)
  {
    AssertThrow(p.n_state_variables() == static_cast<int>(state_variable_names.size()),
                dealii::ExcMessage(state_variable_count_mismatch(p.n_state_variables(), state_variable_names)));
    std::vector<typename dealii::Particles::ParticleHandler<dim>::particle_iterator> removed;
    int i = 0;
    for (auto particle = handler.begin(); particle != handler.end(); ++particle, ++i)
      {
        if (p.material[i] < 0)
          {
            removed.push_back(particle);
            continue;
          }
        dealii::Point<dim> x;
        for (int d = 0; d < dim; ++d)
          x[d] = p.position[d][i];
        layout.write(p, i, particle->get_properties().data(), true);
        particle->set_location(x);
        if (grid.n_ranks > 1 && grid.owned_cell(grid.lattice_cell_of(&x[0])) == grid.triangulation.end())
          ++n_sent; // now in another rank's cell (a point on a shared face may stay)
      }
    handler.remove_particles(removed);
    // deal.II finds the new cell among the neighbours of the old one, else in the
    // owned and ghost cells; points in ghost cells go to their owners. The step loop
    // keeps every point closer than one cell to its old cell, so none is lost.
    handler.sort_particles_into_subdomains_and_cells();
    return static_cast<unsigned int>(removed.size());
  }

  template <int dim>
  double MaterialPoints<dim>::imbalance() const
  {
    return imbalance(static_cast<double>(handler.n_locally_owned_particles()));
  }

  template <int dim>
  double MaterialPoints<dim>::imbalance(const double n_local_points) const
  {
    // The work model of the partition's cell weights: cells (or only those with points)
    // plus weighted points.
    double cells = 0;
    if (empty_cells_weigh)
      cells = double(grid.distributed ? grid.distributed->n_locally_owned_active_cells() :
                                        grid.triangulation.n_active_cells());
    else
      for (const auto &cell : grid.triangulation.active_cell_iterators())
        cells += cell->is_locally_owned() && handler.n_particles_in_cell(cell) > 0 ? 1 : 0;
    const double local = cells * grid.lattice_cells_per_grid_cell + point_weight * n_local_points;
    const double most  = dealii::Utilities::MPI::max(local, grid.communicator);
    const double total = dealii::Utilities::MPI::sum(local, grid.communicator);
    return total > 0 ? most * grid.n_ranks / total : 1.0;
  }

  template <int dim>
  bool MaterialPoints<dim>::refine_near_points(const std::function<void()> &before_refining)
  {
    if (!grid.coarse_away_from_material())
      return false;
    std::vector<long> own; // (the handler's points come cell by cell: few repeats kept)
    for (const auto &particle : handler)
      {
        const dealii::Point<dim> x = particle.get_location();
        if (const long b = grid.block_of(&x[0]); own.empty() || own.back() != b)
          own.push_back(b);
      }
    if (!grid.fine_region_misses(blocks_of_every_rank(std::move(own), grid.communicator)))
      return false;
    if (before_refining)
      before_refining();
    // As repartition(): the handler packs its points with their cells, p4est refines and
    // moves cells by weight, the handler unpacks them on the new owners (children included).
    while (grid.flag_cells_to_refine())
      {
        handler.prepare_for_coarsening_and_refinement();
        grid.triangulation.execute_coarsening_and_refinement();
        handler.unpack_after_coarsening_and_refinement();
      }
    ++grid.n_refinements;
    grid.distribute_nodes();
    for (const auto &particle : handler) // a point's stencil must find its nodes
      AssertThrow(grid.is_fine(particle.get_surrounding_cell()),
                  dealii::ExcMessage("Internal error: a material point lies in a coarse cell of deal.II's grid "
                                     "after it was refined near the material."));
    return true;
  }

  template <int dim>
  void MaterialPoints<dim>::repartition()
  {
    // As deal.II's step-68: the handler packs its points with their cells, p4est moves
    // cells by weight, the handler unpacks them on the new owners.
    handler.prepare_for_coarsening_and_refinement();
    AssertThrow(grid.distributed != nullptr,
                dealii::ExcMessage("repartition needs the distributed grid of a run on several ranks"));
    grid.distributed->repartition();
    handler.unpack_after_coarsening_and_refinement();
    grid.distribute_nodes();
  }

  template struct PointSnapshot<2>;
  template struct PointSnapshot<3>;
  template class MaterialPoints<2>;
  template class MaterialPoints<3>;
  template std::vector<GeneratedBody<2>> generate_bodies<2>(const Parameters &);
  template void points_of_bodies(const std::vector<GeneratedBody<2>> &, const HostGrid<2, double> &,
                                 HostPoints<2, double> &, PointLabels<2> &);
  template void points_of_bodies(const std::vector<GeneratedBody<3>> &, const HostGrid<3, double> &,
                                 HostPoints<3, double> &, PointLabels<3> &);
  template std::vector<GeneratedBody<3>> generate_bodies<3>(const Parameters &);
} // namespace mpm
