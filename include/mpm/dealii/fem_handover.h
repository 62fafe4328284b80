// The state of a deal.II FEM analysis as material points: the hand-over from a pre-failure
// analysis (gravity loading, a slope brought near failure) to MPM run-out.
//
//   std::map<types::material_id, mpm::HandoverMaterial> materials{{0, {0, 2000.}}};
//   auto body = mpm::points_at_quadrature_points(dof_handler, displacement, quadrature,
//                                                state_of_quadrature_point, materials);
//   mpm::Simulator<dim> simulator(parameters, communicator);
//   simulator.setup({body});
//
// Placement (a): one material point per quadrature point of every locally owned cell, in the
// deformed configuration: position x = X + u(X), deformation gradient F = I + grad u, volume
// det(F) JxW, mass = density JxW (JxW in the mesh's reference configuration), small strain
// sym(grad u), and the quadrature point's stress, plastic strain and state variables. The MPM background grid
// is the prm's (Grid), independent of the FEM mesh; points outside it are refused by setup().
// Placement (b), points on the MPM's lattice with the state projected: fem_handover_lattice.h.
// The state a quadrature point gives: handover/quadrature_point_state.h. Header-only: it is
// instantiated for the user's vector type.
#pragma once

#include <mpm/core/config.h>
#include <mpm/dealii/material_points.h>
#include <mpm/handover/quadrature_point_state.h>

#include <deal.II/base/exceptions.h>
#include <deal.II/base/quadrature.h>
#include <deal.II/base/quadrature_point_data.h>
#include <deal.II/base/tensor.h>
#include <deal.II/dofs/dof_handler.h>
#include <deal.II/fe/fe_values.h>
#include <deal.II/fe/fe_values_extractors.h>
#include <deal.II/fe/mapping_q1.h>

#include <cmath>
#include <functional>
#include <map>
#include <string>
#include <type_traits>
#include <vector>

namespace mpm
{
  namespace internal
  {
    template <typename VectorType, typename = void>
    struct has_ghost_elements_query : std::false_type
    {};
    template <typename VectorType>
    struct has_ghost_elements_query<VectorType, std::void_t<decltype(std::declval<const VectorType &>().has_ghost_elements())>>
      : std::true_type
    {};

    // The checks both placements make of their input; throw naming what is wrong.
    template <int dim, typename VectorType>
    void check_handover_input(const dealii::DoFHandler<dim> &dof_handler, const VectorType &displacement,
                              const QuadraturePointStateFunction<dim> &state)
    {
      const dealii::FiniteElement<dim> &fe = dof_handler.get_fe();
      AssertThrow(fe.n_components() >= static_cast<unsigned int>(dim),
                  dealii::ExcMessage("FEM hand-over: the finite element " + fe.get_name() + " has " +
                                     std::to_string(fe.n_components()) + " vector component(s); the displacement needs " +
                                     std::to_string(dim) + " (e.g. FESystem<dim>(FE_Q<dim>(2), dim))."));
      AssertThrow(displacement.size() == dof_handler.n_dofs(),
                  dealii::ExcMessage("FEM hand-over: the displacement vector has " + std::to_string(displacement.size()) +
                                     " entries, the DoFHandler " + std::to_string(dof_handler.n_dofs()) + " DoFs."));
      AssertThrow(static_cast<bool>(state), dealii::ExcMessage("FEM hand-over: no quadrature-point state was given."));
      if constexpr (has_ghost_elements_query<VectorType>::value)
        AssertThrow(displacement.has_ghost_elements() ||
                      dealii::Utilities::MPI::n_mpi_processes(dof_handler.get_communicator()) == 1,
                    dealii::ExcMessage("FEM hand-over: the displacement vector must hold ghost values (a vector "
                                       "initialised with the locally relevant DoFs) on several MPI ranks."));
    }

    // The state variables of quadrature point q of `cell` into point i; the first point fixes
    // their number, every other must give as many.
    template <int dim, typename Cell>
    void set_state_variables(HostPoints<dim, double> &p, const int i, const std::vector<double> &values,
                             const Cell &cell, const unsigned int q)
    {
      if (i == 0)
        p.set_n_state_variables(static_cast<int>(values.size()));
      AssertThrow(static_cast<int>(values.size()) == p.n_state_variables(),
                  dealii::ExcMessage("FEM hand-over: quadrature point " + std::to_string(q) + " of cell " +
                                     cell->id().to_string() + " gives " + std::to_string(values.size()) +
                                     " state variable(s), the first quadrature point " +
                                     std::to_string(p.n_state_variables()) + "."));
      for (int k = 0; k < p.n_state_variables(); ++k)
        p.state_variables[k][i] = values[k];
    }

    // Small strain sym(grad u) of point i, Voigt xx, yy, zz, xy, yz, xz with tensor shear components.
    template <int dim>
    void set_small_strain(HostPoints<dim, double> &p, const int i, const dealii::Tensor<2, dim> &grad_u)
    {
      const int voigt[3][3] = {{0, 3, 5}, {3, 1, 4}, {5, 4, 2}};
      for (int c = 0; c < n_voigt; ++c)
        p.strain[c][i] = 0;
      for (int d = 0; d < dim; ++d)
        for (int e = d; e < dim; ++e)
          p.strain[voigt[d][e]][i] = 0.5 * (grad_u[d][e] + grad_u[e][d]);
    }

    // The state function of a CellDataStorage (step-44's quadrature-point history).
    template <int dim, typename CellIteratorType, typename DataType>
    QuadraturePointStateFunction<dim> state_from_storage(const dealii::CellDataStorage<CellIteratorType, DataType> &history)
    {
      static_assert(std::is_base_of<QuadraturePointState, DataType>::value,
                    "the quadrature-point data type must derive from mpm::QuadraturePointState");
      return [&history](const typename dealii::DoFHandler<dim>::active_cell_iterator &cell, const unsigned int q) {
        const auto data = history.try_get_data(CellIteratorType(cell));
        AssertThrow(data && q < data->size(),
                    dealii::ExcMessage("FEM hand-over: the quadrature-point history holds no state for point " +
                                       std::to_string(q) + " of cell " + cell->id().to_string() + "."));
        return static_cast<const QuadraturePointState &>(*(*data)[q]);
      };
    }
  } // namespace internal

  // Placement (a), with the state of each quadrature point from a function (cell, q) -> state.
  // displacement: the FEM solution on dof_handler, whose first dim vector components are
  // the displacement (any FE_Q(p)^dim or a system whose first components are); a distributed
  // vector must hold the ghost values of the locally relevant DoFs.
  template <int dim, typename VectorType>
  GeneratedBody<dim> points_at_quadrature_points(const dealii::DoFHandler<dim> &dof_handler,
                                                 const VectorType &displacement,
                                                 const dealii::Quadrature<dim> &quadrature,
                                                 const QuadraturePointStateFunction<dim> &state,
                                                 const std::map<dealii::types::material_id, HandoverMaterial> &materials,
                                                 const dealii::Mapping<dim> &mapping = dealii::StaticMappingQ1<dim>::mapping)
  {
    const dealii::FiniteElement<dim> &fe = dof_handler.get_fe();
    internal::check_handover_input(dof_handler, displacement, state);

    dealii::FEValues<dim> fe_values(mapping, fe, quadrature,
                                    dealii::update_values | dealii::update_gradients |
                                      dealii::update_quadrature_points | dealii::update_JxW_values);
    const dealii::FEValuesExtractors::Vector u(0);
    const unsigned int                       n_q = quadrature.size();
    std::vector<dealii::Tensor<1, dim>>      u_q(n_q);
    std::vector<dealii::Tensor<2, dim>>      grad_u_q(n_q);

    GeneratedBody<dim>       body;
    HostPoints<dim, double> &p = body.points;
    long                     n_cells = 0;
    for (const auto &cell : dof_handler.active_cell_iterators())
      if (cell->is_locally_owned())
        ++n_cells;
    p.resize(static_cast<int>(n_cells * n_q));
    int i = 0;
    for (const auto &cell : dof_handler.active_cell_iterators())
      {
        if (!cell->is_locally_owned())
          continue;
        const auto found = materials.find(cell->material_id());
        AssertThrow(found != materials.end(),
                    dealii::ExcMessage("FEM hand-over: cell " + cell->id().to_string() + " has material_id " +
                                       std::to_string(int(cell->material_id())) +
                                       ", which the map of materials given to the hand-over does not name."));
        const HandoverMaterial material = found->second;
        fe_values.reinit(cell);
        fe_values[u].get_function_values(displacement, u_q);
        fe_values[u].get_function_gradients(displacement, grad_u_q);
        for (unsigned int q = 0; q < n_q; ++q, ++i)
          {
            const QuadraturePointState s = state(cell, q);
            dealii::Tensor<2, dim>     F = grad_u_q[q];
            for (int d = 0; d < dim; ++d)
              F[d][d] += 1;
            const double J  = dealii::determinant(F);
            const double V0 = fe_values.JxW(q);
            AssertThrow(J > 0, dealii::ExcMessage("FEM hand-over: det F = " + std::to_string(J) + " <= 0 at quadrature point " +
                                                  std::to_string(q) + " of cell " + cell->id().to_string() + "."));
            for (int d = 0; d < dim; ++d)
              {
                p.position[d][i] = fe_values.quadrature_point(q)[d] + u_q[q][d];
                p.velocity[d][i] = 0;
                // GIMP's domain: the cube of the point's volume (Simulator::setup caps it at half a cell).
                p.initial_domain_half_length[d][i] = 0.5 * std::pow(V0, 1.0 / dim);
                p.domain_half_length[d][i]         = 0.5 * std::pow(J * V0, 1.0 / dim);
                for (int e = 0; e < dim; ++e)
                  p.deformation_gradient[d * dim + e][i] = F[d][e];
              }
            internal::set_small_strain(p, i, grad_u_q[q]);
            for (int c = 0; c < n_voigt; ++c)
              p.stress[c][i] = s.stress[c];
            if (dim == 2)
              p.stress[4][i] = p.stress[5][i] = 0; // plane strain: no out-of-plane shear
            p.plastic_strain[i] = s.plastic_strain;
            internal::set_state_variables(p, i, s.state_variables, cell, q);
            p.initial_volume[i] = V0;
            p.volume[i]         = J * V0;
            p.mass[i]           = material.density * V0;
            p.material[i]       = static_cast<int>(material.material);
            p.material_field[i] = 0; // no random field: Simulator::setup refuses a material with one
          }
      }
    return body;
  }

  // The same with the states in deal.II's CellDataStorage (step-44's quadrature-point
  // history), whose data type derives from QuadraturePointState.
  template <int dim, typename VectorType, typename CellIteratorType, typename DataType>
  GeneratedBody<dim> points_at_quadrature_points(const dealii::DoFHandler<dim> &dof_handler,
                                                 const VectorType &displacement,
                                                 const dealii::Quadrature<dim> &quadrature,
                                                 const dealii::CellDataStorage<CellIteratorType, DataType> &history,
                                                 const std::map<dealii::types::material_id, HandoverMaterial> &materials,
                                                 const dealii::Mapping<dim> &mapping = dealii::StaticMappingQ1<dim>::mapping)
  {
    return points_at_quadrature_points(dof_handler, displacement, quadrature,
                                       internal::state_from_storage<dim>(history), materials, mapping);
  }
} // namespace mpm
