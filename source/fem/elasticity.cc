// The linear-elasticity reference: the only file that instantiates deal.II's FE and
// Trilinos machinery (they are heavy to compile).

#include <lacerta/base/exceptions.h>
#include <lacerta/fem/elasticity.h>
#include <lacerta/fem/subspace_iteration.h>
#include <lacerta/mesh/triangulation_conversion.h>

#include <deal.II/base/function.h>
#include <deal.II/base/parameter_handler.h>
#include <deal.II/base/quadrature_lib.h>
#include <deal.II/distributed/fully_distributed_tria.h>
#include <deal.II/dofs/dof_handler.h>
#include <deal.II/dofs/dof_tools.h>
#include <deal.II/fe/fe_simplex_p.h>
#include <deal.II/fe/fe_system.h>
#include <deal.II/fe/fe_values.h>
#include <deal.II/fe/mapping_fe.h>
#include <deal.II/grid/tria.h>
#include <deal.II/grid/tria_description.h>
#include <deal.II/lac/affine_constraints.h>
#include <deal.II/lac/solver_cg.h>
#include <deal.II/lac/trilinos_precondition.h>
#include <deal.II/lac/trilinos_sparse_matrix.h>
#include <deal.II/lac/trilinos_sparsity_pattern.h>
#include <deal.II/lac/trilinos_vector.h>

#include <Epetra_CrsMatrix.h>
#include <algorithm>
#include <cmath>

namespace lacerta::fem
{
  using namespace dealii;
  using VectorType = TrilinosWrappers::MPI::Vector;
  using MatrixType = TrilinosWrappers::SparseMatrix;

  namespace
  {
    /**
     * dst = A src through Epetra. TrilinosWrappers::SparseMatrix::vmult is a template
     * whose enable_if return type gcc and clang mangle differently, so code compiled by
     * clang (the fuzzing build, doc/reliability.md) could not call the instance in
     * Debian's gcc-built deal.II; Epetra's Multiply is a plain member function.
     */
    void
    multiply(const MatrixType &a, VectorType &dst, const VectorType &src)
    {
      const int error =
        a.trilinos_matrix().Multiply(false, src.trilinos_vector(), dst.trilinos_vector());
      AssertThrow(error == 0, MatrixType::ExcTrilinosError(error));
    }


    /// A matrix that SolverCG multiplies with through multiply().
    struct EpetraOperator
    {
      const MatrixType &matrix;

      void
      vmult(VectorType &dst, const VectorType &src) const
      {
        multiply(matrix, dst, src);
      }
    };
  } // namespace

  void
  SolverParameters::declare_parameters(ParameterHandler &prm)
  {
    prm.declare_entry("Degree",
                      "2",
                      Patterns::Integer(1, 2),
                      "Polynomial degree of the FE_SimplexP elements (1 or 2).");
    prm.declare_entry("Solver tolerance",
                      "1e-10",
                      Patterns::Double(1e-14, 1e-2),
                      "Relative residual reduction at which the CG solver stops.");
    prm.declare_entry("Maximum iterations",
                      "5000",
                      Patterns::Integer(10, 1000000),
                      "CG iterations before a solve counts as failed.");
  }


  void
  SolverParameters::parse_parameters(ParameterHandler &prm)
  {
    degree         = prm.get_integer("Degree");
    tolerance      = prm.get_double("Solver tolerance");
    max_iterations = prm.get_integer("Maximum iterations");
  }


  namespace
  {
    /**
     * The id of the edge (@p a, @p b) of tetrahedron @p t of @p mesh, from the
     * tetrahedron's own edge ids: after a cut the mesh's edge list is no longer sorted,
     * so it cannot be searched.
     */
    unsigned int
    edge_of_tet(const mesh::TetMesh &mesh,
                const unsigned int   t,
                const unsigned int   a,
                const unsigned int   b)
    {
      const auto &vertices = mesh.tet(t);
      for (unsigned int k = 0; k < 6; ++k)
      {
        const unsigned int p = vertices[mesh::TetMesh::edge_vertices[k][0]];
        const unsigned int q = vertices[mesh::TetMesh::edge_vertices[k][1]];
        if ((p == a && q == b) || (p == b && q == a))
          return mesh.tet_edges(t)[k];
      }
      throw_error("FEM reference: vertices ",
                  a,
                  " and ",
                  b,
                  " are no edge of tetrahedron ",
                  t,
                  ".");
    }
  } // namespace


  /**
   * Where a degree of freedom sits on the Problem's mesh: the vertex a (b == a) or the
   * midpoint of the edge (a, b), and its component.
   */
  struct DofNode
  {
    types::global_dof_index dof;
    unsigned int            a, b, component;
    /// The mesh's id of edge (a, b) for an edge node (mesh.get_edges() order).
    unsigned int edge;
  };


  struct ElasticitySolver::Implementation
  {
    Implementation(const Problem          &problem,
                   const SolverParameters &parameters,
                   MPI_Comm                communicator);

    void
    assemble();

    /// Assembles k K + m M with the homogeneous constraints into @p matrix.
    void
    assemble_constrained(double k, double m, MatrixType &matrix);

    /// The prescribed displacements at time t on the constrained dofs, zero elsewhere.
    void
    prescribed_values(double t, VectorType &values) const;

    /// Body load plus the point forces of time t.
    void
    load(double t, VectorType &f) const;

    /**
     * Solves A u = f with u = u_D on the constrained dofs: @p full is A without
     * constraints, @p constrained A with them. @p u enters as the initial guess (its
     * constrained entries are ignored) and leaves as the solution.
     */
    void
    solve(const MatrixType                         &constrained,
          const TrilinosWrappers::PreconditionBase &preconditioner,
          const MatrixType                         &full,
          const VectorType                         &f,
          const VectorType                         &u_d,
          VectorType                               &u);

    /// Makes @p v a vector of the owned dofs, allocating only if it is not one yet.
    void
    ensure_layout(VectorType &v) const;

    void
    make_amg(const MatrixType &matrix, TrilinosWrappers::PreconditionAMG &amg) const;

    NodalField
    gather(const VectorType &u) const;

    const Problem                                problem;
    const SolverParameters                       parameters;
    MPI_Comm                                     communicator;
    parallel::fullydistributed::Triangulation<3> triangulation;
    FESystem<3>                                  fe;
    MappingFE<3>                                 mapping;
    QGaussSimplex<3>                             quadrature;
    DoFHandler<3>                                dof_handler;
    IndexSet                                     owned, relevant;
    AffineConstraints<double>                    constraints;
    std::vector<DofNode>                         owned_nodes;
    MatrixType                                   stiffness, mass, constrained_stiffness;
    VectorType                                   body_load;
    TrilinosWrappers::PreconditionAMG            stiffness_amg;
    bool                                         stiffness_amg_ready = false;
    unsigned int                                 iterations          = 0;

    // Newmark state. The effective matrix (with and without constraints) and its AMG
    // depend only on the time step: built once in start_dynamic(), reused every step.
    double                               time_step = 0, time = 0;
    MatrixType                           effective, effective_full;
    TrilinosWrappers::PreconditionAMG    effective_amg;
    TrilinosWrappers::PreconditionJacobi effective_jacobi;
    // Which of the two preconditions the effective matrix (see start_dynamic()).
    const TrilinosWrappers::PreconditionBase *effective_preconditioner = nullptr;
    VectorType                                u, v, a;
    // Work vectors of advance() and solve(), kept so that a time step allocates nothing.
    VectorType rhs, work, damped, product, u_d, u_new, residual, correction;
    // Per-vertex buffers of the Problem's callbacks (3 per vertex).
    mutable std::vector<double> vertex_values;
  };


  ElasticitySolver::Implementation::Implementation(const Problem          &problem_in,
                                                   const SolverParameters &parameters_in,
                                                   MPI_Comm                comm)
      : problem(problem_in)
      , parameters(parameters_in)
      , communicator(comm)
      , triangulation(comm)
      , fe(FE_SimplexP<3>(parameters_in.degree), 3)
      , mapping(FE_SimplexP<3>(1))
      , quadrature(parameters_in.degree + 1)
  {
    const mesh::TetMesh &mesh = *problem.mesh;
    if (problem.prescribed.size() != mesh.n_vertices())
      throw_error("FEM reference: the problem marks ",
                  problem.prescribed.size(),
                  " vertices as prescribed or free, the mesh has ",
                  mesh.n_vertices(),
                  ".");

    // Partition: contiguous blocks of the spatially sorted tetrahedra, so that the
    // partition is deterministic and needs no graph partitioner.
    Triangulation<3> serial;
    mesh::tet_mesh_to_triangulation(mesh, serial);
    const unsigned int n_ranks = Utilities::MPI::n_mpi_processes(communicator);
    const std::size_t  n_cells = serial.n_active_cells();
    for (const auto &cell : serial.active_cell_iterators())
      cell->set_subdomain_id(static_cast<types::subdomain_id>(
        std::size_t(cell->active_cell_index()) * n_ranks / n_cells));
    triangulation.create_triangulation(
      TriangulationDescription::Utilities::create_description_from_triangulation(
        serial, communicator));

    dof_handler.reinit(triangulation);
    dof_handler.distribute_dofs(fe);
    owned = dof_handler.locally_owned_dofs();
    DoFTools::extract_locally_relevant_dofs(dof_handler, relevant);

    // Which mesh vertex or edge every dof sits on. A coarse cell keeps its index in the
    // serial triangulation, which is the tetrahedron's index in the mesh; the vertices
    // are matched by position, since deal.II may order a cell's vertices differently.
    const std::vector<Point<3>> &unit_points =
      fe.base_element(0).get_unit_support_points();
    std::vector<std::array<unsigned int, 2>> node_vertices(unit_points.size());
    const ReferenceCell                      tet = ReferenceCells::Tetrahedron;
    for (unsigned int k = 0; k < unit_points.size(); ++k)
    {
      node_vertices[k] = {numbers::invalid_unsigned_int, numbers::invalid_unsigned_int};
      for (unsigned int i = 0; i < 4; ++i)
        for (unsigned int j = i; j < 4; ++j)
          if ((unit_points[k] - 0.5 * (tet.vertex<3>(i) + tet.vertex<3>(j))).norm()
              < 1e-12)
            node_vertices[k] = {i, j};
      AssertThrow(node_vertices[k][0] != numbers::invalid_unsigned_int,
                  ExcMessage(
                    "FE_SimplexP node neither on a vertex nor an edge midpoint"));
    }

    constraints.reinit(relevant);
    std::vector<types::global_dof_index> dofs(fe.n_dofs_per_cell());
    std::vector<bool>                    seen(relevant.n_elements(), false);
    for (const auto &cell : dof_handler.active_cell_iterators())
    {
      if (cell->is_artificial())
        continue;
      const unsigned int          t = cell->id().get_coarse_cell_id();
      std::array<unsigned int, 4> vertex{};
      for (unsigned int i = 0; i < 4; ++i)
      {
        double best = 1e300;
        for (const unsigned int m : mesh.tet(t))
        {
          const auto  &p = mesh.vertex(m);
          const double d = cell->vertex(i).distance(Point<3>(p[0], p[1], p[2]));
          if (d < best)
          {
            best      = d;
            vertex[i] = m;
          }
        }
      }
      cell->get_dof_indices(dofs);
      for (unsigned int i = 0; i < fe.n_dofs_per_cell(); ++i)
      {
        const auto [component, node] = fe.system_to_component_index(i);
        const unsigned int a         = vertex[node_vertices[node][0]];
        const unsigned int b         = vertex[node_vertices[node][1]];
        const auto         local     = relevant.index_within_set(dofs[i]);
        if (seen[local])
          continue;
        seen[local] = true;
        if (problem.prescribed[a] && problem.prescribed[b])
          constraints.add_line(dofs[i]);
        if (owned.is_element(dofs[i]))
          owned_nodes.push_back(
            {dofs[i],
             std::min(a, b),
             std::max(a, b),
             component,
             a == b ? mesh::invalid_index : edge_of_tet(mesh, t, a, b)});
      }
    }
    constraints.close();
    assemble();
  }


  void
  ElasticitySolver::Implementation::assemble()
  {
    TrilinosWrappers::SparsityPattern pattern(owned, owned, relevant, communicator);
    DoFTools::make_sparsity_pattern(dof_handler, pattern, constraints, true);
    pattern.compress();
    stiffness.reinit(pattern);
    mass.reinit(pattern);
    constrained_stiffness.reinit(pattern);
    effective.reinit(pattern);
    body_load.reinit(owned, communicator);

    const unsigned int                   n = fe.n_dofs_per_cell();
    FEValues<3>                          fe_values(mapping,
                          fe,
                          quadrature,
                          update_values | update_gradients | update_quadrature_points
                            | update_JxW_values);
    FullMatrix<double>                   local_k(n, n), local_m(n, n);
    Vector<double>                       local_f(n);
    std::vector<types::global_dof_index> dofs(n);
    const double                         nu = problem.poisson_ratio;
    for (const auto &cell : dof_handler.active_cell_iterators())
    {
      if (!cell->is_locally_owned())
        continue;
      fe_values.reinit(cell);
      local_k = 0;
      local_m = 0;
      local_f = 0;
      for (const unsigned int q : fe_values.quadrature_point_indices())
      {
        const Point<3> &x      = fe_values.quadrature_point(q);
        const double    E      = problem.youngs_modulus->value(x);
        const double    rho    = problem.density->value(x);
        const double    lambda = E * nu / ((1 + nu) * (1 - 2 * nu));
        const double    mu     = E / (2 * (1 + nu));
        const double    dx     = fe_values.JxW(q);
        for (unsigned int i = 0; i < n; ++i)
        {
          const unsigned int ci = fe.system_to_component_index(i).first;
          const auto        &gi = fe_values.shape_grad(i, q);
          const double       vi = fe_values.shape_value(i, q);
          for (unsigned int j = 0; j < n; ++j)
          {
            const unsigned int cj = fe.system_to_component_index(j).first;
            const auto        &gj = fe_values.shape_grad(j, q);
            // σ(u):ε(v) = λ div u div v + μ (∂_j u_i ∂_i v_j + ∂_j u_i ∂_j v_i).
            local_k(i, j) += (gi[ci] * gj[cj] * lambda + gi[cj] * gj[ci] * mu
                              + (ci == cj ? gi * gj * mu : 0.0))
                             * dx;
            if (ci == cj)
              local_m(i, j) += rho * vi * fe_values.shape_value(j, q) * dx;
          }
          local_f(i) += rho * problem.body_acceleration[ci] * vi * dx;
        }
      }
      cell->get_dof_indices(dofs);
      stiffness.add(dofs, local_k);
      mass.add(dofs, local_m);
      constraints.distribute_local_to_global(local_k, dofs, constrained_stiffness);
      for (unsigned int i = 0; i < n; ++i)
        body_load(dofs[i]) += local_f(i);
    }
    stiffness.compress(VectorOperation::add);
    mass.compress(VectorOperation::add);
    constrained_stiffness.compress(VectorOperation::add);
    body_load.compress(VectorOperation::add);
  }


  void
  ElasticitySolver::Implementation::assemble_constrained(const double k,
                                                         const double m,
                                                         MatrixType  &matrix)
  {
    // Rebuilt from the unconstrained matrices cell by cell would repeat the quadrature;
    // instead the constrained stiffness and the mass are combined here, and the
    // constrained rows get the diagonal k K_ii + m M_ii that keeps them well scaled.
    matrix = 0;
    matrix.add(k, constrained_stiffness);
    for (const auto &row : owned_nodes)
      if (constraints.is_constrained(row.dof))
        matrix.add(row.dof, row.dof, m * mass.diag_element(row.dof));
      else
        for (auto entry = mass.begin(row.dof); entry != mass.end(row.dof); ++entry)
          if (!constraints.is_constrained(entry->column()))
            matrix.add(row.dof, entry->column(), m * entry->value());
    matrix.compress(VectorOperation::add);
  }


  void
  ElasticitySolver::Implementation::prescribed_values(const double t,
                                                      VectorType  &values) const
  {
    ensure_layout(values);
    values = 0;
    if (!problem.displacement)
      return;
    std::vector<double> &u = vertex_values;
    u.assign(3 * problem.mesh->n_vertices(), 0.0);
    problem.displacement(t, u);
    for (const auto &node : owned_nodes)
      if (constraints.is_constrained(node.dof))
        values(node.dof) =
          0.5 * (u[3 * node.a + node.component] + u[3 * node.b + node.component]);
    values.compress(VectorOperation::insert);
  }


  void
  ElasticitySolver::Implementation::load(const double t, VectorType &f) const
  {
    f = body_load;
    if (!problem.point_forces)
      return;
    std::vector<double> &forces = vertex_values;
    forces.assign(3 * problem.mesh->n_vertices(), 0.0);
    problem.point_forces(t, forces);
    for (const auto &node : owned_nodes)
      if (node.a == node.b)
        f(node.dof) += forces[3 * node.a + node.component];
    f.compress(VectorOperation::add);
  }


  void
  ElasticitySolver::Implementation::make_amg(const MatrixType                  &matrix,
                                             TrilinosWrappers::PreconditionAMG &amg) const
  {
    // Translations as near-null space: ML then aggregates the three displacement
    // components of a node together, as elasticity needs.
    TrilinosWrappers::PreconditionAMG::AdditionalData data;
    std::vector<std::vector<bool>>                    modes;
    DoFTools::extract_constant_modes(dof_handler, ComponentMask(3, true), modes);
    data.constant_modes        = modes;
    data.elliptic              = true;
    data.higher_order_elements = parameters.degree > 1;
    data.smoother_sweeps       = 2;
    data.aggregation_threshold = 0.02;
    amg.initialize(matrix, data);
  }


  void
  ElasticitySolver::Implementation::ensure_layout(VectorType &v) const
  {
    if (v.size() != dof_handler.n_dofs() || !(v.locally_owned_elements() == owned))
      v.reinit(owned, communicator);
  }


  void
  ElasticitySolver::Implementation::solve(
    const MatrixType                         &constrained,
    const TrilinosWrappers::PreconditionBase &preconditioner,
    const MatrixType                         &full,
    const VectorType                         &f,
    const VectorType                         &u_d,
    VectorType                               &result)
  {
    // u = u_D + w with w = 0 on the constrained dofs: A_c w = f - A u_D there. The
    // guess for w is the incoming u minus u_D (a Newmark step passes its predictor).
    ensure_layout(residual);
    ensure_layout(correction);
    ensure_layout(result);
    multiply(full, residual, u_d);
    residual.sadd(-1.0, 1.0, f);
    constraints.set_zero(residual);
    // The tolerance is relative to this right-hand side, not to the initial residual:
    // a good initial guess then saves iterations instead of tightening the goal.
    const double norm = residual.l2_norm();
    correction        = result;
    correction -= u_d;
    constraints.set_zero(correction);
    iterations = 0;
    if (norm > 0)
    {
      SolverControl control(parameters.max_iterations, parameters.tolerance * norm);
      SolverCG<VectorType> cg(control);
      try
      {
        cg.solve(EpetraOperator{constrained}, correction, residual, preconditioner);
      }
      catch (const SolverControl::NoConvergence &e)
      {
        throw_error("FEM reference: CG did not reach the relative residual ",
                    parameters.tolerance,
                    " in 'Maximum iterations' = ",
                    parameters.max_iterations,
                    " iterations (residual ",
                    e.last_residual / norm,
                    ").");
      }
      iterations = control.last_step();
    }
    else
      correction = 0;
    constraints.set_zero(correction);
    result = u_d;
    result += correction;
  }


  NodalField
  ElasticitySolver::Implementation::gather(const VectorType &values) const
  {
    const mesh::TetMesh &mesh = *problem.mesh;
    NodalField           field;
    field.degree = parameters.degree;
    field.vertex.assign(3 * mesh.n_vertices(), 0.0);
    if (field.degree == 2)
      field.edge.assign(3 * mesh.n_edges(), 0.0);
    for (const auto &node : owned_nodes)
    {
      const double value = values(node.dof);
      if (node.a == node.b)
        field.vertex[3 * node.a + node.component] = value;
      else
        field.edge[3 * node.edge + node.component] = value;
    }
    // Every dof is owned by exactly one rank: a sum gathers the field everywhere.
    Utilities::MPI::sum(field.vertex, communicator, field.vertex);
    if (field.degree == 2)
      Utilities::MPI::sum(field.edge, communicator, field.edge);
    return field;
  }


  ElasticitySolver::ElasticitySolver(const Problem          &problem,
                                     const SolverParameters &parameters,
                                     MPI_Comm                communicator)
      : impl(std::make_unique<Implementation>(problem, parameters, communicator))
  {
  }


  ElasticitySolver::~ElasticitySolver() = default;


  NodalField
  ElasticitySolver::solve_static(const double t)
  {
    Implementation &s = *impl;
    if (!s.stiffness_amg_ready)
    {
      s.make_amg(s.constrained_stiffness, s.stiffness_amg);
      s.stiffness_amg_ready = true;
    }
    VectorType f, u_d;
    s.load(t, f);
    s.prescribed_values(t, u_d);
    s.u.reinit(s.owned, s.communicator);
    s.solve(s.constrained_stiffness, s.stiffness_amg, s.stiffness, f, u_d, s.u);
    return s.gather(s.u);
  }


  namespace
  {
    /// Up to this K_ii / ((4/dt²) M_ii), Newmark preconditions with Jacobi, not AMG.
    constexpr double jacobi_stiffness_ratio = 100;
  } // namespace


  void
  ElasticitySolver::start_dynamic(const double dt)
  {
    Implementation &s = *impl;
    s.time_step       = dt;
    s.time            = 0;
    const double a0 = 4 / (dt * dt), a1 = 2 / dt;
    const double c = s.problem.mass_damping, beta = s.problem.stiffness_damping;
    // K_eff = K + (2/dt) C + (4/dt²) M with C = c M + β K, with the constraints (for CG
    // and AMG) and without (to apply to the prescribed values).
    s.assemble_constrained(1 + a1 * beta, a0 + a1 * c, s.effective);
    s.effective_full.reinit(s.stiffness);
    s.effective_full = 0;
    s.effective_full.add(1 + a1 * beta, s.stiffness);
    s.effective_full.add(a0 + a1 * c, s.mass);
    // Which preconditioner: at the steps a Newmark run takes, (4/dt²) M dominates K,
    // K_eff is about as well conditioned as M, and CG with Jacobi needs few iterations
    // of one matrix product each, where every AMG cycle costs several products and a
    // coarse direct solve. The largest ratio of the diagonals, K_ii / ((4/dt²) M_ii),
    // bounds how far K shifts the spectrum; AMG only when it is large.
    double stiffness_ratio = 0;
    for (const auto &node : s.owned_nodes)
      if (!s.constraints.is_constrained(node.dof))
        stiffness_ratio = std::max(stiffness_ratio,
                                   (1 + a1 * beta) * s.stiffness.diag_element(node.dof)
                                     / ((a0 + a1 * c) * s.mass.diag_element(node.dof)));
    stiffness_ratio = Utilities::MPI::max(stiffness_ratio, s.communicator);
    if (stiffness_ratio < jacobi_stiffness_ratio)
    {
      s.effective_jacobi.initialize(s.effective);
      s.effective_preconditioner = &s.effective_jacobi;
    }
    else
    {
      s.make_amg(s.effective, s.effective_amg);
      s.effective_preconditioner = &s.effective_amg;
    }

    s.prescribed_values(0, s.u);
    s.v.reinit(s.owned, s.communicator);
    // Consistent initial acceleration: M a = f - K u - C v on the free dofs.
    VectorType f;
    s.load(0, f);
    VectorType ku(s.owned, s.communicator);
    multiply(s.stiffness, ku, s.u);
    f -= ku;
    VectorType zero(s.owned, s.communicator);
    MatrixType constrained_mass;
    constrained_mass.reinit(s.effective);
    s.assemble_constrained(0, 1, constrained_mass);
    TrilinosWrappers::PreconditionJacobi jacobi;
    jacobi.initialize(constrained_mass);
    s.a.reinit(s.owned, s.communicator);
    s.solve(constrained_mass, jacobi, s.mass, f, zero, s.a);
  }


  void
  ElasticitySolver::advance()
  {
    Implementation &s  = *impl;
    const double    dt = s.time_step;
    AssertThrow(dt > 0, ExcMessage("start_dynamic() must come before advance()"));
    const double a0 = 4 / (dt * dt), a1 = 2 / dt;
    const double c = s.problem.mass_damping, beta = s.problem.stiffness_damping;
    const double t = s.time + dt;

    // rhs = f + M (a0 u + (4/dt) v + a) + C (a1 u + v).
    s.ensure_layout(s.work);
    s.ensure_layout(s.damped);
    s.ensure_layout(s.product);
    s.load(t, s.rhs);
    s.work = s.u;
    s.work *= a0;
    s.work.add(4 / dt, s.v);
    s.work += s.a;
    s.damped = s.u;
    s.damped *= a1;
    s.damped += s.v;
    s.work.add(c, s.damped);
    multiply(s.mass, s.product, s.work);
    s.rhs += s.product;
    if (beta > 0)
    {
      multiply(s.stiffness, s.product, s.damped);
      s.rhs.add(beta, s.product);
    }

    // Initial guess: the step with unchanged acceleration, u + dt v + dt²/2 a; CG then
    // only corrects the change of acceleration.
    s.prescribed_values(t, s.u_d);
    s.ensure_layout(s.u_new);
    s.u_new = s.u;
    s.u_new.add(dt, s.v, dt * dt / 2, s.a);
    s.solve(
      s.effective, *s.effective_preconditioner, s.effective_full, s.rhs, s.u_d, s.u_new);

    // a_new = a0 (u_new - u) - (4/dt) v - a; v_new = v + dt/2 (a + a_new). The work
    // vector holds a_new.
    s.work = s.u_new;
    s.work -= s.u;
    s.work *= a0;
    s.work.add(-4 / dt, s.v);
    s.work -= s.a;
    s.v.add(dt / 2, s.a, dt / 2, s.work);
    s.a.swap(s.work);
    s.u.swap(s.u_new);
    s.time = t;
  }


  double
  ElasticitySolver::time() const
  {
    return impl->time;
  }


  NodalField
  ElasticitySolver::displacement() const
  {
    return impl->gather(impl->u);
  }


  std::vector<double>
  ElasticitySolver::lowest_frequencies(const unsigned int n)
  {
    Implementation &s = *impl;
    if (!s.stiffness_amg_ready)
    {
      s.make_amg(s.constrained_stiffness, s.stiffness_amg);
      s.stiffness_amg_ready = true;
    }
    // Start vectors from the dof's global index only, so that every partition starts
    // from the same block and converges to the same values.
    const auto start = [&](VectorType &x, const unsigned int j)
    {
      x.reinit(s.owned, s.communicator);
      for (const auto i : s.owned)
        x(i) = std::sin(1.0 + 12.9898 * double(i) + 78.233 * double(j + 1));
      x.compress(VectorOperation::insert);
    };
    const SolverParameters &quiet   = s.parameters;
    const auto              solve_k = [&](VectorType &dst, const VectorType &src)
    {
      dst = 0;
      if (src.l2_norm() == 0)
        return;
      SolverControl        control(quiet.max_iterations, quiet.tolerance * src.l2_norm());
      SolverCG<VectorType> cg(control);
      cg.solve(EpetraOperator{s.constrained_stiffness}, dst, src, s.stiffness_amg);
    };
    return to_frequencies(lowest_eigenvalues<VectorType>(
      n,
      start,
      [&](VectorType &dst, const VectorType &src) { multiply(s.stiffness, dst, src); },
      [&](VectorType &dst, const VectorType &src) { multiply(s.mass, dst, src); },
      solve_k,
      [&](VectorType &x) { s.constraints.set_zero(x); }));
  }


  unsigned long
  ElasticitySolver::n_dofs() const
  {
    return impl->dof_handler.n_dofs();
  }


  unsigned int
  ElasticitySolver::last_iterations() const
  {
    return impl->iterations;
  }
} // namespace lacerta::fem
