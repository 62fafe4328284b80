// Placement (b) of the FEM hand-over: material points on the MPM's own lattice (n^dim per MPM
// cell, where a prm body would put them), with the FEM's state projected onto them.
//
//   mpm::LatticeHandover<dim> lattice = mpm::lattice_handover<dim>(parameters, 2);
//   auto body = mpm::points_on_lattice(dof_handler, displacement, quadrature, history, materials,
//                                      lattice);
//   simulator.setup({body});
//
// Every lattice point x inside the deformed FEM body (x = X + u(X) for some X of a cell) becomes a
// material point at x: volume (h/n)^dim, deformation gradient F = I + grad u at X, mass
// density * (h/n)^dim / det F, small strain sym(grad u). Stress, plastic strain and the model's
// further state variables come from the quadrature points of X's cell by a cell-wise L2
// projection onto discontinuous polynomials of degree k (FE_DGQ(k); the DG mass matrix is
// cell-local, so no global solve), evaluated at X; a plastic strain that the projection takes
// below zero is set to zero.
// A point on the boundary between cells takes the cell with the smallest CellId, so that the
// points do not depend on how the mesh is partitioned; each rank returns the points of its own
// cells (Simulator::setup gathers them).
//
// Placement (a) (fem_handover.h) keeps the FEM's quadrature exactly; (b) gives points the MPM's
// usual spacing and GIMP domains that tile the body without gaps or overlaps, at the price of the
// projection error (order k + 1 in the FEM's cell size for a smooth state).
#pragma once

#include <mpm/dealii/fem_handover.h>
#include <mpm/dealii/parameters.h>

#include <deal.II/base/bounding_box.h>
#include <deal.II/base/geometry_info.h>
#include <deal.II/fe/fe_dgq.h>
#include <deal.II/fe/mapping_q.h>
#include <deal.II/fe/mapping_q_eulerian.h>
#include <deal.II/grid/cell_id.h>
#include <deal.II/lac/full_matrix.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <vector>

namespace mpm
{
  // Where the lattice points are: origin + (k + 1/2) h / n along each axis, k an integer, the same
  // points the prm's bodies get with "Points per cell direction = n".
  template <int dim>
  struct LatticeHandover
  {
    dealii::Point<dim> origin;                        // the MPM grid's lower corner
    double             cell_size                 = 0; // h of the MPM grid
    unsigned int       points_per_cell_direction = 2; // n
    // Degree k of the projection of the quadrature-point state; -1: the displacement's FE degree.
    // The quadrature must have at least (k + 1)^dim points (k + 1 per direction for a Gauss rule).
    int projection_degree = -1;
  };

  // The lattice of an MPM scene's grid (Grid/Lower corner, Grid/Cell size).
  template <int dim>
  LatticeHandover<dim> lattice_handover(const Parameters &parameters, const unsigned int points_per_cell_direction,
                                        const int projection_degree = -1)
  {
    LatticeHandover<dim> lattice;
    for (int d = 0; d < dim; ++d)
      lattice.origin[d] = parameters.lower.at(d);
    lattice.cell_size                 = parameters.cell_size;
    lattice.points_per_cell_direction = points_per_cell_direction;
    lattice.projection_degree         = projection_degree;
    return lattice;
  }

  template <int dim, typename VectorType>
  GeneratedBody<dim> points_on_lattice(const dealii::DoFHandler<dim> &dof_handler,
                                       const VectorType &displacement,
                                       const dealii::Quadrature<dim> &quadrature,
                                       const QuadraturePointStateFunction<dim> &state,
                                       const std::map<dealii::types::material_id, HandoverMaterial> &materials,
                                       const LatticeHandover<dim> &lattice)
  {
    using dealii::ExcMessage;
    const dealii::FiniteElement<dim> &fe = dof_handler.get_fe();
    internal::check_handover_input(dof_handler, displacement, state);
    const unsigned int n = lattice.points_per_cell_direction;
    AssertThrow(n >= 1 && lattice.cell_size > 0,
                ExcMessage("FEM hand-over on the lattice: the cell size must be > 0 and the points per cell "
                           "direction >= 1 (got " + std::to_string(lattice.cell_size) + ", " + std::to_string(n) +
                           ")."));
    const unsigned int degree = lattice.projection_degree < 0 ? fe.degree : lattice.projection_degree;

    // The cell-local L2 projection: coefficients C = M^-1 B with M_ij = sum_q phi_i phi_j JxW and
    // B_ic = sum_q phi_i s_c JxW; the inverse is well defined when the quadrature is exact enough.
    const dealii::FE_DGQ<dim> dg(degree);
    const unsigned int        n_dg = dg.n_dofs_per_cell(), n_q = quadrature.size();
    AssertThrow(n_q >= n_dg, ExcMessage("FEM hand-over on the lattice: a projection of degree " +
                                        std::to_string(degree) + " needs at least " + std::to_string(n_dg) +
                                        " quadrature points per cell (" + std::to_string(degree + 1) +
                                        " per direction); the quadrature has " + std::to_string(n_q) +
                                        ". Give a lower LatticeHandover::projection_degree or a finer quadrature."));
    dealii::FullMatrix<double> phi(n_q, n_dg);
    for (unsigned int q = 0; q < n_q; ++q)
      for (unsigned int j = 0; j < n_dg; ++j)
        phi(q, j) = dg.shape_value(j, quadrature.point(q));

    // The FEM's own geometry (MappingQ of the FE's degree), and the deformed one x = X + u(X).
    const unsigned int                     mapping_degree = std::max(1u, fe.degree);
    const dealii::MappingQ<dim>            reference(mapping_degree);
    const dealii::MappingQEulerian<dim, VectorType> deformed(mapping_degree, dof_handler, displacement);
    dealii::FEValues<dim> fe_values(reference, fe, quadrature, dealii::update_JxW_values);

    // 1. Each lattice point inside a cell of this rank (owned or ghost), with the cell of the
    // smallest CellId among those containing it.
    struct Candidate
    {
      dealii::CellId                                        id;
      typename dealii::DoFHandler<dim>::active_cell_iterator cell;
      dealii::Point<dim>                                    unit;
    };
    const double                            dx = lattice.cell_size / n;
    std::map<std::array<long, dim>, Candidate> found;
    for (const auto &cell : dof_handler.active_cell_iterators())
      {
        if (cell->is_artificial())
          continue;
        const dealii::BoundingBox<dim> box = deformed.get_bounding_box(cell);
        // Support points bound a curved cell only roughly: a margin of a tenth of its largest side.
        double margin = 0;
        for (int d = 0; d < dim; ++d)
          margin = std::max(margin, 0.1 * box.side_length(d));
        std::array<long, dim> first, last;
        for (int d = 0; d < dim; ++d)
          {
            first[d] = static_cast<long>(std::ceil((box.lower_bound(d) - margin - lattice.origin[d]) / dx - 0.5));
            last[d]  = static_cast<long>(std::floor((box.upper_bound(d) + margin - lattice.origin[d]) / dx - 0.5));
          }
        std::array<long, dim> k = first;
        bool                  more = true;
        for (int d = 0; d < dim; ++d)
          more = more && first[d] <= last[d];
        while (more)
          {
            dealii::Point<dim> x;
            for (int d = 0; d < dim; ++d)
              x[d] = lattice.origin[d] + (k[d] + 0.5) * dx;
            try
              {
                const dealii::Point<dim> unit = deformed.transform_real_to_unit_cell(cell, x);
                if (dealii::GeometryInfo<dim>::is_inside_unit_cell(unit, 1e-10))
                  {
                    const auto it = found.find(k);
                    if (it == found.end() || cell->id() < it->second.id)
                      found[k] = Candidate{cell->id(), cell, unit};
                  }
              }
            catch (const typename dealii::Mapping<dim>::ExcTransformationFailed &)
              {
                // x is far outside this cell: Newton's method of the inverse mapping diverged.
              }
            int d = 0;
            for (; d < dim; ++d)
              {
                if (++k[d] <= last[d])
                  break;
                k[d] = first[d];
              }
            more = d < dim;
          }
      }

    // 2. The points of this rank's own cells, cell by cell.
    std::map<dealii::CellId, std::vector<dealii::Point<dim>>> by_cell;
    std::map<dealii::CellId, std::vector<dealii::Point<dim>>> lattice_point_of;
    std::map<dealii::CellId, typename dealii::DoFHandler<dim>::active_cell_iterator> cell_of;
    long n_points = 0;
    for (const auto &[k, candidate] : found)
      if (candidate.cell->is_locally_owned())
        {
          by_cell[candidate.id].push_back(candidate.unit);
          dealii::Point<dim> x;
          for (int d = 0; d < dim; ++d)
            x[d] = lattice.origin[d] + (k[d] + 0.5) * dx;
          lattice_point_of[candidate.id].push_back(x);
          cell_of.emplace(candidate.id, candidate.cell);
          ++n_points;
        }

    GeneratedBody<dim>       body;
    HostPoints<dim, double> &p = body.points;
    p.resize(static_cast<int>(n_points));
    // The state variables: as many as the first quadrature point of this rank's cells gives.
    if (!by_cell.empty())
      p.set_n_state_variables(static_cast<int>(state(cell_of.begin()->second, 0).state_variables.size()));
    const int n_state = p.n_state_variables();
    // Projected components: 6 stresses, the plastic strain, the state variables.
    const int                                n_components = n_voigt + 1 + n_state;
    const dealii::FEValuesExtractors::Vector u(0);
    const double                             volume = std::pow(dx, dim);
    int                                      i      = 0;
    dealii::FullMatrix<double>               mass(n_dg, n_dg), inverse(n_dg, n_dg);
    std::vector<std::vector<double>>         coefficients(n_dg, std::vector<double>(n_components));
    for (const auto &[id, units] : by_cell)
      {
        const auto &cell  = cell_of.at(id);
        const auto  match = materials.find(cell->material_id());
        AssertThrow(match != materials.end(),
                    ExcMessage("FEM hand-over: cell " + id.to_string() + " has material_id " +
                               std::to_string(int(cell->material_id())) +
                               ", which the map of materials given to the hand-over does not name."));

        // The projection of the cell's quadrature-point state (6 stresses, plastic strain, state variables).
        fe_values.reinit(cell);
        mass = 0;
        for (auto &c : coefficients)
          std::fill(c.begin(), c.end(), 0.0);
        std::vector<std::vector<double>> rhs(n_dg, std::vector<double>(n_components, 0.0));
        for (unsigned int q = 0; q < n_q; ++q)
          {
            const QuadraturePointState s = state(cell, q);
            AssertThrow(static_cast<int>(s.state_variables.size()) == n_state,
                        ExcMessage("FEM hand-over: quadrature point " + std::to_string(q) + " of cell " +
                                   id.to_string() + " gives " + std::to_string(s.state_variables.size()) +
                                   " state variable(s), the first quadrature point " + std::to_string(n_state) + "."));
            for (unsigned int a = 0; a < n_dg; ++a)
              {
                const double weight = phi(q, a) * fe_values.JxW(q);
                for (unsigned int b = 0; b < n_dg; ++b)
                  mass(a, b) += phi(q, a) * phi(q, b) * fe_values.JxW(q);
                for (int c = 0; c < n_voigt; ++c)
                  rhs[a][c] += weight * s.stress[c];
                rhs[a][n_voigt] += weight * s.plastic_strain;
                for (int k = 0; k < n_state; ++k)
                  rhs[a][n_voigt + 1 + k] += weight * s.state_variables[k];
              }
          }
        inverse.invert(mass);
        // Enough quadrature points can still be placed so that M is singular (a rule that is not a
        // tensor product): then M M^-1 is not I.
        double off_identity = 0;
        for (unsigned int a = 0; a < n_dg; ++a)
          for (unsigned int b = 0; b < n_dg; ++b)
            {
              double product = 0;
              for (unsigned int c = 0; c < n_dg; ++c)
                product += mass(a, c) * inverse(c, b);
              const double error = std::abs(product - (a == b ? 1.0 : 0.0));
              if (!(error <= off_identity)) // NaN too, which std::max would drop
                off_identity = error;
            }
        AssertThrow(std::isfinite(off_identity) && off_identity < 1e-8,
                    ExcMessage("FEM hand-over on the lattice: the quadrature cannot determine a projection of degree " +
                               std::to_string(degree) + " in cell " + id.to_string() +
                               " (its mass matrix is singular). Give a lower LatticeHandover::projection_degree or "
                               "a Gauss rule with degree + 1 points per direction."));
        for (unsigned int a = 0; a < n_dg; ++a)
          for (unsigned int b = 0; b < n_dg; ++b)
            for (int c = 0; c < n_components; ++c)
              coefficients[a][c] += inverse(a, b) * rhs[b][c];

        // The kinematics at the points' reference positions, on the undeformed cell.
        dealii::FEValues<dim> at_points(reference, fe, dealii::Quadrature<dim>(units),
                                        dealii::update_values | dealii::update_gradients |
                                          dealii::update_quadrature_points);
        at_points.reinit(cell);
        std::vector<dealii::Tensor<1, dim>> u_p(units.size());
        std::vector<dealii::Tensor<2, dim>> grad_u_p(units.size());
        at_points[u].get_function_values(displacement, u_p);
        at_points[u].get_function_gradients(displacement, grad_u_p);
        const std::vector<dealii::Point<dim>> &xs = lattice_point_of.at(id);
        for (unsigned int j = 0; j < units.size(); ++j, ++i)
          {
            dealii::Tensor<2, dim> F = grad_u_p[j];
            for (int d = 0; d < dim; ++d)
              F[d][d] += 1;
            const double J = dealii::determinant(F);
            AssertThrow(J > 0, ExcMessage("FEM hand-over: det F = " + std::to_string(J) + " <= 0 in cell " +
                                          id.to_string() + "."));
            for (int d = 0; d < dim; ++d)
              {
                p.position[d][i]                   = xs[j][d];
                p.velocity[d][i]                   = 0;
                p.domain_half_length[d][i]         = 0.5 * dx;
                p.initial_domain_half_length[d][i] = 0.5 * std::pow(volume / J, 1.0 / dim);
                for (int e = 0; e < dim; ++e)
                  p.deformation_gradient[d * dim + e][i] = F[d][e];
              }
            internal::set_small_strain(p, i, grad_u_p[j]);
            std::vector<double> values(n_components, 0.0);
            for (unsigned int a = 0; a < n_dg; ++a)
              {
                const double phi_a = dg.shape_value(a, units[j]);
                for (int c = 0; c < n_components; ++c)
                  values[c] += coefficients[a][c] * phi_a;
              }
            for (int c = 0; c < n_voigt; ++c)
              p.stress[c][i] = values[c];
            if (dim == 2)
              p.stress[4][i] = p.stress[5][i] = 0; // plane strain: no out-of-plane shear
            // The projection may overshoot below zero next to a yielded region; eps_p >= 0.
            p.plastic_strain[i] = std::max(0.0, values[n_voigt]);
            // State variables as projected: their bounds, if any, are the model's to know.
            for (int k = 0; k < n_state; ++k)
              p.state_variables[k][i] = values[n_voigt + 1 + k];
            p.initial_volume[i] = volume / J;
            p.volume[i]         = volume;
            p.mass[i]           = match->second.density * volume / J;
            p.material[i]       = static_cast<int>(match->second.material);
            p.material_field[i] = 0;
          }
      }
    return body;
  }

  // The same with the states in deal.II's CellDataStorage (its data type derives from
  // QuadraturePointState).
  template <int dim, typename VectorType, typename CellIteratorType, typename DataType>
  GeneratedBody<dim> points_on_lattice(const dealii::DoFHandler<dim> &dof_handler,
                                       const VectorType &displacement,
                                       const dealii::Quadrature<dim> &quadrature,
                                       const dealii::CellDataStorage<CellIteratorType, DataType> &history,
                                       const std::map<dealii::types::material_id, HandoverMaterial> &materials,
                                       const LatticeHandover<dim> &lattice)
  {
    return points_on_lattice(dof_handler, displacement, quadrature, internal::state_from_storage<dim>(history),
                             materials, lattice);
  }
} // namespace mpm
