/**
 * @file
 * The linear-elasticity reference (added to the paper): FE_SimplexP of degree 1 or 2
 * on the tetrahedra of a TetMesh, static (Trilinos CG + AMG) and dynamic (Newmark,
 * average acceleration, consistent mass), in parallel over MPI.
 */
#pragma once

#include <lacerta/fem/nodal_field.h>
#include <lacerta/mesh/tet_mesh.h>

#include <array>
#include <functional>
#include <memory>
#include <mpi.h>
#include <vector>

namespace dealii
{
  template <int dim, typename Number>
  class Function;
  class ParameterHandler;
} // namespace dealii

namespace lacerta::fem
{
  /**
   * A linear-elasticity problem stated in the spring model's terms, so that both models
   * see the same object, material, constraints and loads: the rest mesh, the material
   * fields, which vertices have prescribed motion (and what it is), the uniform body
   * acceleration and the point forces at the vertices.
   */
  struct Problem
  {
    /// The tetrahedra in their rest configuration.
    const mesh::TetMesh *mesh = nullptr;
    /// Density σ(x) (kg/m³) and Young's modulus E(x) (Pa).
    const dealii::Function<3, double> *density = nullptr, *youngs_modulus = nullptr;
    /// Poisson ratio ν.
    double poisson_ratio = 0.25;
    /// Rayleigh damping C = c M + β K, the continuum form of the spring model's particle
    /// damping c (1/s) and damping along springs β (s).
    double mass_damping = 0, stiffness_damping = 0;
    /// Uniform body acceleration (m/s²), e.g. gravity.
    std::array<double, 3> body_acceleration = {{0, 0, 0}};
    /// 1 for every vertex whose motion is prescribed.
    std::vector<unsigned char> prescribed;
    /// Writes the prescribed displacement at time t of every vertex (3 per vertex; only
    /// the prescribed vertices are read). Empty: prescribed vertices stay at rest.
    std::function<void(double, std::vector<double> &)> displacement;
    /// Writes the point forces (N) at time t on every vertex (3 per vertex). Empty: none.
    std::function<void(double, std::vector<double> &)> point_forces;
  };


  /**
   * Parameters of the FEM solver (`subsection FEM` where a scene uses it).
   */
  struct SolverParameters
  {
    /// Polynomial degree of FE_SimplexP, 1 or 2.
    unsigned int degree = 2;
    /// Relative residual reduction at which CG stops.
    double tolerance = 1e-10;
    /// CG iterations before the solve is an Error.
    unsigned int max_iterations = 5000;

    /// Declares the entries in the current subsection.
    static void
    declare_parameters(dealii::ParameterHandler &prm);

    /// Reads the entries declared by declare_parameters().
    void
    parse_parameters(dealii::ParameterHandler &prm);
  };


  /**
   * Linear elasticity on a Problem, distributed over the ranks of a communicator with a
   * parallel::fullydistributed::Triangulation (each rank owns a contiguous block of the
   * spatially sorted tetrahedra). The results are gathered on every rank as NodalFields
   * on the Problem's mesh, so callers never see deal.II types.
   *
   * Dirichlet conditions: a vertex node is prescribed if its vertex is; a P2 edge node
   * if both ends are, with the mean of their displacements (exact for the fixed and
   * affine motions scenes use). Point forces act on the vertex nodes.
   */
  class ElasticitySolver
  {
  public:
    /// Sets up the triangulation, dofs and constraints and assembles K and M.
    ElasticitySolver(const Problem          &problem,
                     const SolverParameters &parameters,
                     MPI_Comm                communicator = MPI_COMM_WORLD);

    ~ElasticitySolver();

    /// Static equilibrium under the loads and prescribed displacements of time @p t.
    NodalField
    solve_static(double t = 0);

    /**
     * Starts a Newmark (average acceleration: β = 1/4, γ = 1/2) integration from rest
     * at time 0 with time step @p time_step; the initial acceleration is the
     * consistent one, M a = f - K u.
     */
    void
    start_dynamic(double time_step);

    /// Advances the Newmark integration by one time step.
    void
    advance();

    /// Simulated time of the Newmark integration (s).
    double
    time() const;

    /// The displacement of the last solve or Newmark step.
    NodalField
    displacement() const;

    /**
     * The @p n lowest eigenfrequencies (Hz) of K u = ω² M u with the prescribed vertices
     * held, by subspace iteration with the CG-AMG solver.
     */
    std::vector<double>
    lowest_frequencies(unsigned int n);

    /// Number of degrees of freedom.
    unsigned long
    n_dofs() const;

    /// CG iterations of the last solve.
    unsigned int
    last_iterations() const;

  private:
    struct Implementation;
    std::unique_ptr<Implementation> impl;
  };
} // namespace lacerta::fem
