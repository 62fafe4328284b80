#include <mpm/core/material/small_strain_update.h>
#include <mpm/core/material/strength_reduction.h>
#include <mpm/fem/quasi_static_solver.h>

#include <deal.II/base/exceptions.h>
#include <deal.II/base/mpi.h>
#include <deal.II/base/timer.h>
#include <deal.II/dofs/dof_tools.h>
#include <deal.II/fe/fe_q.h>
#include <deal.II/fe/fe_values.h>
#include <deal.II/lac/dynamic_sparsity_pattern.h>
#include <deal.II/lac/full_matrix.h>
#include <deal.II/lac/solver_cg.h>
#include <deal.II/lac/solver_control.h>
#include <deal.II/lac/solver_gmres.h>
#include <deal.II/lac/sparsity_tools.h>
#include <deal.II/lac/trilinos_precondition.h>
#include <deal.II/lac/trilinos_solver.h>
#include <deal.II/numerics/data_out.h>
#include <deal.II/numerics/vector_tools.h>

#include <algorithm>
#include <cmath>
#include <iostream>

namespace mpm::fem
{
  using namespace dealii;

  namespace
  {
    // The Voigt components a dim-dimensional symmetric gradient has (plane strain: xx, yy, xy),
    // their tensor indices, and their weight in sigma : eps (2 for a shear component).
    template <int dim>
    struct VoigtComponents;
    template <>
    struct VoigtComponents<2>
    {
      static constexpr int n            = 3;
      static constexpr int index[3]     = {0, 1, 3};
      static constexpr int row[3]       = {0, 1, 0};
      static constexpr int column[3]    = {0, 1, 1};
      static constexpr double weight[3] = {1, 1, 2};
    };
    template <>
    struct VoigtComponents<3>
    {
      static constexpr int n            = 6;
      static constexpr int index[6]     = {0, 1, 2, 3, 4, 5};
      static constexpr int row[6]       = {0, 1, 2, 0, 1, 0};
      static constexpr int column[6]    = {0, 1, 2, 1, 2, 2};
      static constexpr double weight[6] = {1, 1, 1, 2, 2, 2};
    };

    template <int dim>
    void to_voigt(const SymmetricTensor<2, dim> &e, double out[n_voigt])
    {
      using V = VoigtComponents<dim>;
      std::fill(out, out + n_voigt, 0.0);
      for (int k = 0; k < V::n; ++k)
        out[V::index[k]] = e[V::row[k]][V::column[k]];
    }

    // The state after the increment from the committed point state to total strain eps.
    struct UpdatedPoint
    {
      SymTensor<double> stress;
      double            plastic_strain;
      Tangent           C;
      ReturnMode        mode;
    };

    UpdatedPoint update_point(const MaterialParameters<double> &m, const QuadraturePointHistory &h,
                              const double eps[n_voigt])
    {
      UpdatedPoint      p;
      SymTensor<double> d_eps;
      for (int c = 0; c < n_voigt; ++c)
        {
          d_eps[c]    = eps[c] - h.strain[c];
          p.stress[c] = h.stress[c];
        }
      p.plastic_strain = h.plastic_strain;
      p.mode           = small_strain_update(m, d_eps, p.stress, p.plastic_strain, p.C).mode;
      return p;
    }
  } // namespace

  template <int dim>
  QuasiStaticSolver<dim>::QuasiStaticSolver(parallel::distributed::Triangulation<dim> &triangulation,
                                            const std::map<types::material_id, FemMaterial> &materials,
                                            const PrefailureParameters &parameters,
                                            const std::vector<double>  &gravity_vector)
    : communicator(triangulation.get_communicator())
    , triangulation(triangulation)
    , materials(materials)
    , settings(parameters)
    , fe(FE_Q<dim>(parameters.degree), dim)
    , dofs(triangulation)
    , quadrature_formula(parameters.degree + 1)
  {
    for (int d = 0; d < dim; ++d)
      gravity[d] = gravity_vector.at(d);
    for (const auto &cell : triangulation.active_cell_iterators())
      if (cell->is_locally_owned())
        AssertThrow(this->materials.count(cell->material_id()),
                    ExcMessage("FEM stage: cell " + cell->id().to_string() + " has material_id " +
                               std::to_string(cell->material_id()) + ", which no material is given for."));

    dofs.distribute_dofs(fe);
    owned = dofs.locally_owned_dofs();
    DoFTools::extract_locally_relevant_dofs(dofs, relevant);
    setup_constraints(parameters);

    DynamicSparsityPattern dsp(relevant);
    DoFTools::make_sparsity_pattern(dofs, dsp, constraints, false);
    SparsityTools::distribute_sparsity_pattern(dsp, owned, communicator, relevant);
    tangent.reinit(owned, owned, dsp, communicator);
    elastic_stiffness.reinit(owned, owned, dsp, communicator);
    residual.reinit(owned, communicator);
    solution.reinit(owned, relevant, communicator);
    committed.reinit(owned, relevant, communicator);
    monitor_reference.reinit(owned, relevant, communicator);

    histories.initialize(triangulation.begin_active(), triangulation.end(), quadrature_formula.size());
    // Zero stress, strain and plastic strain everywhere (the default-constructed history).
    for (const auto &cell : triangulation.active_cell_iterators())
      if (cell->is_locally_owned())
        histories.initialize(cell, quadrature_formula.size());

    // The norm of the full gravity load: the reference of Newton's tolerance. At zero stress
    // the residual is the load itself.
    load_norm = assemble(committed, 1.0, 1.0, Matrix::none);
    AssertThrow(load_norm > 0, ExcMessage("FEM stage: the gravity load is zero (Solver/Gravity); the "
                                          "pre-failure analyses load the body by its weight."));
  }

  template <int dim>
  void QuasiStaticSolver<dim>::setup_constraints(const PrefailureParameters &parameters)
  {
    constraints.clear();
    constraints.reinit(relevant);
    DoFTools::make_hanging_node_constraints(dofs, constraints);
    // Periodic pairs before the Dirichlet values: a node both periodic and on a fixed boundary
    // is tied to its partner, which carries the fixed value.
    for (const auto &[id, condition] : parameters.boundary_conditions)
      if (condition == BoundaryCondition::periodic && id % 2 == 0)
        DoFTools::make_periodicity_constraints(dofs, id, id + 1, id / 2, constraints);
    // Axes along which some fixed or roller boundary holds the body (bit d): without one, the
    // body could translate freely and no equilibrium exists.
    unsigned int held_axes = 0;
    // Which axes each roller boundary is a plane normal to: every face of the id spans zero
    // along the axis (bit d set), over every rank.
    for (const auto &[id, condition] : parameters.boundary_conditions)
      {
        if (condition == BoundaryCondition::free || condition == BoundaryCondition::periodic)
          continue;
        unsigned int normal_axes = (1u << dim) - 1, n_faces = 0;
        for (const auto &cell : dofs.active_cell_iterators())
          if (cell->is_locally_owned())
            for (const unsigned int f : cell->face_indices())
              if (cell->face(f)->at_boundary() && cell->face(f)->boundary_id() == id)
                {
                  ++n_faces;
                  const double size = cell->face(f)->diameter();
                  for (int d = 0; d < dim; ++d)
                    for (const unsigned int v : cell->face(f)->vertex_indices())
                      if (std::abs(cell->face(f)->vertex(v)[d] - cell->face(f)->vertex(0)[d]) > 1e-10 * size)
                        normal_axes &= ~(1u << d);
                }
        n_faces = Utilities::MPI::sum(n_faces, communicator);
        {
          unsigned int all = normal_axes;
          MPI_Allreduce(&normal_axes, &all, 1, MPI_UNSIGNED, MPI_BAND, communicator);
          normal_axes = all;
        }
        if (n_faces == 0) // e.g. x max of the default list at a slope's toe, or a mistyped id: say so
          {
            if (Utilities::MPI::this_mpi_process(communicator) == 0)
              std::cout << "  note: Pre-failure analysis/Boundary conditions names boundary id " << id
                        << ", which no boundary face of this mesh has; ignored." << std::endl;
            continue;
          }
        held_axes |= condition == BoundaryCondition::fixed ? (1u << dim) - 1 : normal_axes;
        if (condition == BoundaryCondition::fixed)
          VectorTools::interpolate_boundary_values(dofs, id, Functions::ZeroFunction<dim>(dim), constraints);
        else
          {
            int axis = -1;
            for (int d = 0; d < dim; ++d)
              if (normal_axes == (1u << d))
                axis = d;
            AssertThrow(axis >= 0,
                        ExcMessage("Parameter 'Pre-failure analysis/Boundary conditions': boundary id " +
                                   std::to_string(id) + " is a roller, but its faces are not one plane normal to "
                                   "an axis (x, y or z); make it fixed or free, or give the plane its own id."));
            ComponentMask mask(dim, false);
            mask.set(axis, true);
            VectorTools::interpolate_boundary_values(dofs, id, Functions::ZeroFunction<dim>(dim), constraints, mask);
          }
      }
    if (held_axes != (1u << dim) - 1)
      {
        std::string free_axes;
        for (int d = 0; d < dim; ++d)
          if (!(held_axes & (1u << d)))
            free_axes += std::string(free_axes.empty() ? "" : ", ") + "xyz"[d];
        AssertThrow(false, ExcMessage("Parameter 'Pre-failure analysis/Boundary conditions': no fixed or roller "
                                      "boundary of the mesh holds the body along " + free_axes +
                                      ", so it could move freely and has no equilibrium; fix a boundary (e.g. the "
                                      "base: '" + std::to_string(2 * (dim - 1)) + ": fixed')."));
      }
    constraints.close();
  }

  template <int dim>
  double QuasiStaticSolver<dim>::assemble(const TrilinosWrappers::MPI::Vector &u, const double load_factor,
                                          const double strength_factor, const Matrix matrix)
  {
    const bool                      with_matrix = matrix != Matrix::none;
    TrilinosWrappers::SparseMatrix &A           = matrix == Matrix::elastic ? elastic_stiffness : tangent;
    using V = VoigtComponents<dim>;
    std::map<types::material_id, MaterialParameters<double>> reduced;
    for (const auto &[id, m] : materials)
      reduced[id] = with_reduced_strength(m.parameters, strength_factor);

    FEValues<dim> fe_values(fe, quadrature_formula, update_values | update_gradients | update_JxW_values);
    const FEValuesExtractors::Vector displacement(0);
    const unsigned int               n = fe.n_dofs_per_cell(), n_q = quadrature_formula.size();
    FullMatrix<double>               cell_matrix(n, n);
    Vector<double>                   cell_rhs(n);
    std::vector<types::global_dof_index>         indices(n);
    std::vector<SymmetricTensor<2, dim>>         strains(n_q);
    std::vector<std::array<double, V::n>>        B(n), CB(n);

    if (with_matrix)
      A = 0;
    residual = 0;

    for (const auto &cell : dofs.active_cell_iterators())
      if (cell->is_locally_owned())
        {
          fe_values.reinit(cell);
          fe_values[displacement].get_function_symmetric_gradients(u, strains);
          const MaterialParameters<double> &m       = reduced.at(cell->material_id());
          const double                      density = materials.at(cell->material_id()).density;
          const auto                        points  = histories.get_data(cell);
          Tangent                           elastic_C;
          if (matrix == Matrix::elastic)
            elastic_tangent(m.elastic, elastic_C);
          cell_matrix                               = 0;
          cell_rhs                                  = 0;
          for (unsigned int q = 0; q < n_q; ++q)
            {
              double eps[n_voigt];
              to_voigt(strains[q], eps);
              const UpdatedPoint p = update_point(m, *points[q], eps);
              const auto        &C = matrix == Matrix::elastic ? elastic_C : p.C;

              const double       JxW = fe_values.JxW(q);
              for (unsigned int i = 0; i < n; ++i)
                {
                  const SymmetricTensor<2, dim> e = fe_values[displacement].symmetric_gradient(i, q);
                  double                        internal = 0;
                  for (int k = 0; k < V::n; ++k)
                    {
                      B[i][k] = e[V::row[k]][V::column[k]];
                      internal += V::weight[k] * p.stress[V::index[k]] * B[i][k];
                    }
                  cell_rhs(i) -= (internal - load_factor * density * (gravity * fe_values[displacement].value(i, q))) * JxW;
                }
              if (with_matrix)
                {
                  for (unsigned int j = 0; j < n; ++j)
                    for (int a = 0; a < V::n; ++a)
                      {
                        double s = 0;
                        for (int b = 0; b < V::n; ++b)
                          s += C[V::index[a]][V::index[b]] * B[j][b];
                        CB[j][a] = V::weight[a] * s * JxW;
                      }
                  for (unsigned int i = 0; i < n; ++i)
                    for (unsigned int j = 0; j < n; ++j)
                      {
                        double s = 0;
                        for (int a = 0; a < V::n; ++a)
                          s += B[i][a] * CB[j][a];
                        cell_matrix(i, j) += s;
                      }
                }
            }
          cell->get_dof_indices(indices);
          if (with_matrix)
            constraints.distribute_local_to_global(cell_matrix, cell_rhs, indices, A, residual);
          else
            constraints.distribute_local_to_global(cell_rhs, indices, residual);
        }
    if (with_matrix)
      A.compress(VectorOperation::add);
    residual.compress(VectorOperation::add);
    return residual.l2_norm();
  }

  template <int dim>
  TrilinosWrappers::PreconditionAMG::AdditionalData QuasiStaticSolver<dim>::amg_settings() const
  {
    TrilinosWrappers::PreconditionAMG::AdditionalData data;
    std::vector<std::vector<bool>>                    modes;
    DoFTools::extract_constant_modes(dofs, ComponentMask(dim, true), modes);
    data.constant_modes        = modes;
    data.elliptic              = true;
    data.higher_order_elements = settings.degree > 1;
    data.smoother_sweeps       = 2;
    return data;
  }

  template <int dim>
  void QuasiStaticSolver<dim>::solve_linear(const TrilinosWrappers::SparseMatrix &tangent,
                                            TrilinosWrappers::MPI::Vector &update)
  {
    SolverControl control(5000, 1e-12 * residual.l2_norm());
    if (settings.linear_solver == "direct")
      {
        TrilinosWrappers::SolverDirect direct(control);
        direct.solve(tangent, update, residual);
      }
    else
      {
        TrilinosWrappers::PreconditionAMG amg;
        amg.initialize(tangent, amg_settings());
        SolverGMRES<TrilinosWrappers::MPI::Vector> gmres(control, SolverGMRES<TrilinosWrappers::MPI::Vector>::AdditionalData(100));
        gmres.solve(tangent, update, residual, amg);
      }
    constraints.distribute(update);
  }

  template <int dim>
  NewtonReport QuasiStaticSolver<dim>::solve(const double load_factor, const double strength_factor)
  {
    Timer        timer;
    NewtonReport report;
    TrilinosWrappers::MPI::Vector u(owned, communicator), trial(owned, communicator), update(owned, communicator);
    u        = committed;
    solution = committed;
    double r = assemble(solution, load_factor, strength_factor, Matrix::tangent);
    // Newton's iterate of least residual: where Newton cycles, the initial-stiffness
    // iterations start from there.
    TrilinosWrappers::MPI::Vector best(u);
    double                        r_best = r;
    for (;;)
      {
        if (r < r_best)
          {
            r_best = r;
            best   = u;
          }
        report.residuals.push_back(r / load_norm);
        if (!std::isfinite(r))
          break;
        if (r <= settings.residual_tolerance * load_norm)
          {
            report.converged = true;
            break;
          }
        if (report.iterations == settings.maximum_newton_iterations)
          break;
        update = 0;
        try
          {
            solve_linear(tangent, update);
          }
        catch (const ExceptionBase &) // a singular tangent (a mechanism): Newton cannot go on
          {
            report.singular_tangent = true;
            break;
          }
        ++report.iterations;
        // Backtracking: halve the step until the residual falls (at most 6 times; the last
        // step is taken in any case).
        double alpha = 1, r_trial = 0;
        for (unsigned int halving = 0;; ++halving)
          {
            trial = u;
            trial.add(alpha, update);
            solution = trial;
            r_trial  = assemble(solution, load_factor, strength_factor, Matrix::tangent);
            if (!settings.line_search || r_trial < r || halving == 6)
              break;
            alpha /= 2;
            ++report.line_search_halvings;
          }
        u = trial;
        r = r_trial;
      }
    if (!report.converged && std::isfinite(r) && settings.maximum_initial_stiffness_iterations > 0)
      report.converged = solve_initial_stiffness(best, load_factor, strength_factor, report);
    if (report.converged)
      {
        commit(strength_factor);
        committed = solution;
      }
    else
      solution = committed;
    report.wall_seconds = timer.wall_time();
    return report;
  }

  template <int dim>
  bool QuasiStaticSolver<dim>::solve_initial_stiffness(const TrilinosWrappers::MPI::Vector &start,
                                                       const double load_factor, const double strength_factor,
                                                       NewtonReport &report)
  {
    TrilinosWrappers::MPI::Vector u(start), update(owned, communicator);
    solution = u;
    double r = assemble(solution, load_factor, strength_factor, Matrix::elastic);
    // K_e is factorised (or its AMG built) once for all iterations; a failure of the solver
    // (a singular K_e) ends the attempt like a non-converged one.
    const bool                        direct_solver = settings.linear_solver == "direct";
    SolverControl                     control(1, 0);
    TrilinosWrappers::SolverDirect    direct(control);
    TrilinosWrappers::PreconditionAMG amg;
    try
      {
        if (direct_solver)
          direct.initialize(elastic_stiffness);
        else
          amg.initialize(elastic_stiffness, amg_settings());
      }
    catch (const ExceptionBase &)
      {
        return false;
      }
    for (unsigned int k = 0;; ++k)
      {
        report.residuals.push_back(r / load_norm);
        if (!std::isfinite(r))
          return false;
        if (r <= settings.initial_stiffness_tolerance * load_norm)
          return true;
        if (k == settings.maximum_initial_stiffness_iterations)
          return false;
        update = 0;
        try
          {
            if (direct_solver)
              direct.solve(update, residual);
            else
              {
                // K_e is symmetric positive definite: CG
                SolverControl                            cg_control(5000, 1e-12 * residual.l2_norm());
                SolverCG<TrilinosWrappers::MPI::Vector> cg(cg_control);
                cg.solve(elastic_stiffness, update, residual, amg);
              }
          }
        catch (const ExceptionBase &)
          {
            return false;
          }
        constraints.distribute(update);
        ++report.initial_stiffness_iterations;
        u.add(1.0, update);
        solution = u;
        r        = assemble(solution, load_factor, strength_factor, Matrix::none);
      }
  }

  template <int dim>
  void QuasiStaticSolver<dim>::commit(const double strength_factor)
  {
    FEValues<dim> fe_values(fe, quadrature_formula, update_gradients);
    const FEValuesExtractors::Vector     displacement(0);
    std::vector<SymmetricTensor<2, dim>> strains(quadrature_formula.size());
    for (const auto &cell : dofs.active_cell_iterators())
      if (cell->is_locally_owned())
        {
          fe_values.reinit(cell);
          fe_values[displacement].get_function_symmetric_gradients(solution, strains);
          const MaterialParameters<double> m =
            with_reduced_strength(materials.at(cell->material_id()).parameters, strength_factor);
          const auto points = histories.get_data(cell);
          for (unsigned int q = 0; q < points.size(); ++q)
            {
              double eps[n_voigt];
              to_voigt(strains[q], eps);
              const UpdatedPoint p = update_point(m, *points[q], eps);
              for (int c = 0; c < n_voigt; ++c)
                {
                  points[q]->stress[c] = p.stress[c];
                  points[q]->strain[c] = eps[c];
                }
              points[q]->plastic_strain = p.plastic_strain;
            }
        }
  }

  template <int dim>
  void QuasiStaticSolver<dim>::set_k0_stresses(const double k0)
  {
    const int vertical = dim - 1;
    AssertThrow(gravity.norm() > 0 && std::abs(gravity[vertical]) == gravity.norm(),
                ExcMessage("Pre-failure analysis/Method: the K0 procedure needs gravity along the vertical axis "
                           "(Solver/Gravity)."));
    // Each material id's height range, over every rank.
    std::map<types::material_id, std::pair<double, double>> layers;
    for (const auto &[id, m] : materials)
      {
        double lo = std::numeric_limits<double>::max(), hi = -lo;
        for (const auto &cell : triangulation.active_cell_iterators())
          if (cell->is_locally_owned() && cell->material_id() == id)
            for (const unsigned int v : cell->vertex_indices())
              lo = std::min(lo, cell->vertex(v)[vertical]), hi = std::max(hi, cell->vertex(v)[vertical]);
        layers[id] = {Utilities::MPI::min(lo, communicator), Utilities::MPI::max(hi, communicator)};
      }
    for (auto a = layers.begin(); a != layers.end(); ++a)
      for (auto b = std::next(a); b != layers.end(); ++b)
        if (a->second.first <= a->second.second && b->second.first <= b->second.second)
          AssertThrow(std::min(a->second.second, b->second.second) - std::max(a->second.first, b->second.first) <= 0,
                      ExcMessage("Pre-failure analysis/Method: the K0 procedure takes horizontal layers, but the "
                                 "cells of material ids " + std::to_string(a->first) + " and " +
                                 std::to_string(b->first) + " overlap in height; use gravity loading."));
    const auto overburden = [&](const double z) {
      double weight = 0;
      for (const auto &[id, range] : layers)
        if (z < range.second)
          weight += materials.at(id).density * (range.second - std::max(z, range.first));
      return weight;
    };

    FEValues<dim> fe_values(fe, quadrature_formula, update_quadrature_points);
    for (const auto &cell : dofs.active_cell_iterators())
      if (cell->is_locally_owned())
        {
          fe_values.reinit(cell);
          const LinearElasticParameters<double> &elastic = materials.at(cell->material_id()).parameters.elastic;
          const double K = k0 >= 0 ? k0 : elastic.poissons_ratio / (1 - elastic.poissons_ratio);
          const auto   points = histories.get_data(cell);
          for (unsigned int q = 0; q < points.size(); ++q)
            {
              QuadraturePointHistory &h       = *points[q];
              const double            sigma_v = -gravity.norm() * overburden(fe_values.quadrature_point(q)[vertical]);
              h                               = QuadraturePointHistory();
              h.stress[0] = h.stress[1] = h.stress[2] = K * sigma_v;
              h.stress[dim == 2 ? 1 : 2]              = sigma_v;
            }
        }
    committed = 0;
    solution  = 0;
  }

  template <int dim>
  void QuasiStaticSolver<dim>::set_monitor_reference()
  {
    monitor_reference = committed;
  }

  template <int dim>
  double QuasiStaticSolver<dim>::monitor_displacement(const std::vector<double> &point) const
  {
    // Over the vertices of the owned cells: the one nearest the point (or with the largest
    // displacement); the pair (key, displacement) reduced over the ranks by the key.
    double best_key = std::numeric_limits<double>::max(), best = 0;
    for (const auto &cell : dofs.active_cell_iterators())
      if (cell->is_locally_owned())
        for (const unsigned int v : cell->vertex_indices())
          {
            double norm2 = 0;
            for (int c = 0; c < dim; ++c)
              {
                const auto   i = cell->vertex_dof_index(v, c);
                const double d = committed[i] - monitor_reference[i];
                norm2 += d * d;
              }
            double key = -norm2;
            if (!point.empty())
              {
                key = 0;
                for (int d = 0; d < dim; ++d)
                  key += std::pow(cell->vertex(v)[d] - point[d], 2);
              }
            if (key < best_key)
              best_key = key, best = std::sqrt(norm2);
          }
    struct
    {
      double key;
      int    rank;
    } local{best_key, static_cast<int>(Utilities::MPI::this_mpi_process(communicator))}, global{};
    MPI_Allreduce(&local, &global, 1, MPI_DOUBLE_INT, MPI_MINLOC, communicator);
    double value = global.rank == local.rank ? best : 0;
    return Utilities::MPI::sum(value, communicator);
  }

  template <int dim>
  const DoFHandler<dim> &QuasiStaticSolver<dim>::dof_handler() const
  {
    return dofs;
  }

  template <int dim>
  const TrilinosWrappers::MPI::Vector &QuasiStaticSolver<dim>::displacement() const
  {
    return committed;
  }

  template <int dim>
  const Quadrature<dim> &QuasiStaticSolver<dim>::quadrature() const
  {
    return quadrature_formula;
  }

  template <int dim>
  const QuadraturePointHistory &QuasiStaticSolver<dim>::history(const typename Triangulation<dim>::cell_iterator &cell,
                                                                const unsigned int q) const
  {
    return *histories.get_data(cell)[q];
  }

  template <int dim>
  QuadraturePointStateFunction<dim> QuasiStaticSolver<dim>::state_function() const
  {
    return [this](const typename DoFHandler<dim>::active_cell_iterator &cell, const unsigned int q) {
      return static_cast<const QuadraturePointState &>(history(typename Triangulation<dim>::cell_iterator(cell), q));
    };
  }

  template <int dim>
  types::global_dof_index QuasiStaticSolver<dim>::n_dofs() const
  {
    return dofs.n_dofs();
  }

  template <int dim>
  double QuasiStaticSolver<dim>::max_plastic_strain() const
  {
    double largest = 0;
    for (const auto &cell : triangulation.active_cell_iterators())
      if (cell->is_locally_owned())
        for (const auto &point : histories.get_data(cell))
          largest = std::max(largest, point->plastic_strain);
    return Utilities::MPI::max(largest, communicator);
  }

  template <int dim>
  std::string QuasiStaticSolver<dim>::write_output(const std::string &directory, const std::string &name) const
  {
    DataOut<dim>                                               data_out;
    const std::vector<DataComponentInterpretation::DataComponentInterpretation> vector(
      dim, DataComponentInterpretation::component_is_part_of_vector);
    data_out.attach_dof_handler(dofs);
    data_out.add_data_vector(committed, std::vector<std::string>(dim, "displacement"),
                             DataOut<dim>::type_dof_data, vector);
    // Cell averages of the quadrature-point state.
    const char *stress_names[n_voigt] = {"stress_xx", "stress_yy", "stress_zz", "stress_xy", "stress_yz", "stress_xz"};
    std::vector<Vector<float>> stress(n_voigt, Vector<float>(triangulation.n_active_cells()));
    Vector<float> plastic_strain(triangulation.n_active_cells()), material_id(triangulation.n_active_cells()),
      subdomain(triangulation.n_active_cells());
    for (const auto &cell : triangulation.active_cell_iterators())
      if (cell->is_locally_owned())
        {
          const auto   points = histories.get_data(cell);
          const auto   k      = cell->active_cell_index();
          const double w      = 1.0 / points.size();
          for (const auto &point : points)
            {
              for (int c = 0; c < n_voigt; ++c)
                stress[c][k] += w * point->stress[c];
              plastic_strain[k] += w * point->plastic_strain;
            }
          material_id[k] = cell->material_id();
          subdomain[k]   = triangulation.locally_owned_subdomain();
        }
    for (int c = 0; c < n_voigt; ++c)
      data_out.add_data_vector(stress[c], stress_names[c], DataOut<dim>::type_cell_data);
    data_out.add_data_vector(plastic_strain, "plastic_strain", DataOut<dim>::type_cell_data);
    data_out.add_data_vector(material_id, "material_id", DataOut<dim>::type_cell_data);
    data_out.add_data_vector(subdomain, "subdomain", DataOut<dim>::type_cell_data);
    data_out.build_patches(settings.degree);
    return directory + "/" + data_out.write_vtu_with_pvtu_record(directory + "/", name, 0, communicator, 0, 0);
  }

  template class QuasiStaticSolver<2>;
  template class QuasiStaticSolver<3>;
} // namespace mpm::fem
