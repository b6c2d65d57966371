/**
 * @file
 * The particle system's parameters from the mesh and the materials (Sections 3.1, 3.2).
 */
#pragma once

#include <lacerta/mesh/tet_mesh.h>
#include <lacerta/physics/spring_set.h>

#include <deal.II/lac/full_matrix.h>

#include <array>
#include <optional>
#include <vector>

namespace dealii
{
  template <int dim, typename Number>
  class Function;
}

namespace lacerta::physics
{
  /**
   * Particle masses by Section 3.1: tetrahedron τ gives vertex i the mass
   * ∫_τ σ(x) c_i(x) dx, c_i the barycentric coordinate of vertex i, integrated by a
   * Witherden-Vincent rule exact for σ of polynomial degree up to 2. Each tetrahedron
   * thus gives its vertices exactly ∫_τ σ, and the total mass is ∫σ over the object
   * whatever the tetrahedralisation.
   */
  std::vector<double>
  compute_masses(const mesh::TetMesh &mesh, const dealii::Function<3, double> &density);

  /**
   * ∫_τ σ(x) dx for every tetrahedron, with the rule of compute_masses().
   */
  double
  integrate_over_mesh(const mesh::TetMesh               &mesh,
                      const dealii::Function<3, double> &field);

  /**
   * Springs by Section 3.2: one per unique edge e, stiffness
   * k_e = Σ_{τ ∋ e} E(τ) V(τ) / |e|², E evaluated at the centroid of τ, rest length
   * |e| in the rest configuration. Springs are in the order of mesh.get_edges().
   */
  /**
   * The mass contribution ∫_τ σ c_i of tetrahedron @p t of @p mesh to each of its four
   * vertices (Section 3.1), with the rule of compute_masses(); they add up to ∫_τ σ.
   * The cutter uses it to update the masses around a cut locally.
   */
  std::array<double, 4>
  tet_mass_contributions(const mesh::TetMesh               &mesh,
                         unsigned int                       t,
                         const dealii::Function<3, double> &density);

  /**
   * tet_mass_contributions() for a density that is @p sigma everywhere: the same
   * values to the last bit, without evaluating a Function at the quadrature points.
   */
  std::array<double, 4>
  tet_mass_contributions(const mesh::TetMesh &mesh, unsigned int t, double sigma);

  /**
   * tet_mass_contributions() for a density that is @p sigma everywhere, of a
   * tetrahedron whose volume mesh.volume(t) is @p volume: the same values to the last
   * bit, for a caller that needs the volume for its stiffness too.
   */
  std::array<double, 4>
  constant_density_mass_contributions(double volume, double sigma);

  /**
   * constant_density_mass_contributions() for one density @p sigma and many
   * tetrahedra: the same values to the last bit, with the products of the density and
   * the quadrature rule's barycentric coordinates formed once.
   */
  class ConstantDensityMass
  {
  public:
    /// The contributions for a density that is @p sigma everywhere.
    explicit ConstantDensityMass(double sigma);

    /// The contributions of a tetrahedron of volume @p volume to its four vertices.
    std::array<double, 4>
    operator()(double volume) const;

    /// The number of points of the quadrature rule of compute_masses().
    static constexpr unsigned int n_points = 8;

  private:
    /// σ·c_i at every quadrature point.
    std::array<std::array<double, 4>, n_points> scaled_coordinates;
    /// The quadrature weights, summing to 1.
    std::array<double, n_points> weights;
  };

  /**
   * The value of @p f if it is a scalar dealii::Functions::ConstantFunction or
   * ZeroFunction (so that callers can use the constant-density overload), otherwise
   * nothing.
   */
  std::optional<double>
  constant_value(const dealii::Function<3, double> &f);

  /**
   * The contribution E(centroid) V(τ) of tetrahedron @p t to the numerator of every
   * one of its edges' stiffness k_e = Σ E V / |e|² (Section 3.2).
   */
  double
  tet_stiffness_factor(const mesh::TetMesh               &mesh,
                       unsigned int                       t,
                       const dealii::Function<3, double> &youngs_modulus);

  /// The Lamé parameters {λ, μ} of Young's modulus @p youngs and Poisson ratio @p nu.
  std::array<double, 2>
  lame_parameters(double youngs, double nu);

  /**
   * The 12x12 stiffness matrix of a linear (P1) tetrahedron with vertices @p x and
   * Lamé parameters @p lambda, @p mu, rows and columns ordered (vertex, component).
   */
  dealii::FullMatrix<double>
  p1_element_stiffness(const std::array<mesh::Point3, 4> &x, double lambda, double mu);

  /**
   * The stiffness of edge @p e = (a, b) from the tetrahedra around it, and its rest
   * length, as compute_springs() gives them; local (needs mesh.enable_local_updates()).
   */
  std::array<double, 2>
  edge_spring(const mesh::TetMesh               &mesh,
              unsigned int                       e,
              const dealii::Function<3, double> &youngs_modulus);

  SpringSet
  compute_springs(const mesh::TetMesh               &mesh,
                  const dealii::Function<3, double> &youngs_modulus);

  /**
   * The springs of @p mesh whose cells contribute @p cell_stiffness (per cell, its six
   * edges in local order) to their edges' stiffnesses; an edge no cell gives anything
   * keeps a token 1e-6 of the stiffest spring, as compute_fitted_springs() does.
   */
  SpringSet
  compute_springs(const mesh::TetMesh                      &mesh,
                  const std::vector<std::array<double, 6>> &cell_stiffness);

  /**
   * The paper's rule (Section 3.2): the contributions E V / |e|² of a tetrahedron to
   * its six edges' stiffnesses, from its @p e_times_v = E V (tet_stiffness_factor())
   * and the squares of its edges' rest lengths @p squared_length (local edge order).
   * The one place the rule is written: the assembly, the local updates of cuts, tears
   * and levels of detail and the MT's coarse cells all use it.
   */
  std::array<double, 6>
  paper_edge_stiffnesses(double e_times_v, const std::array<double, 6> &squared_length);

  /**
   * The contributions E V / |e|² of a tetrahedron with rest vertices @p x (positively
   * oriented) and Young's modulus @p youngs_modulus to its six edges' stiffnesses
   * (local order mesh::TetMesh::edge_vertices; Section 3.2).
   */
  std::array<double, 6>
  paper_edge_stiffnesses(const std::array<mesh::Point3, 4> &x, double youngs_modulus);

  /**
   * The contributions of a tetrahedron with rest vertices @p x to its six edges'
   * stiffnesses (local edge order) under compute_fitted_springs()'s rule, with Young's
   * modulus @p youngs_modulus and Poisson ratio @p poisson_ratio.
   */
  std::array<double, 6>
  fitted_edge_stiffnesses(const std::array<mesh::Point3, 4> &x,
                          double                             youngs_modulus,
                          double                             poisson_ratio);

  /**
   * The contributions of tetrahedron @p t to the stiffness of its six edges (local edge
   * order) under compute_fitted_springs()'s rule: the k ≥ 0 that fit its P1 stiffness
   * with E at its centroid and Poisson ratio @p poisson_ratio best.
   */
  std::array<double, 6>
  fitted_edge_stiffnesses(const mesh::TetMesh               &mesh,
                          unsigned int                       t,
                          const dealii::Function<3, double> &youngs_modulus,
                          double                             poisson_ratio);

  /**
   * Springs fitted to linear elasticity (beyond the paper; Lloyd, Székely and Harders,
   * IEEE TVCG 2007): tetrahedron τ gives its six edges the stiffnesses k ≥ 0 that
   * minimise the Frobenius norm |K_τ - Σ_e k_e n_e n_eᵀ blocks| between the linear
   * (P1) FEM stiffness of τ with E at its centroid and Poisson ratio @p poisson_ratio,
   * and the linearised stiffness of its springs. An edge whose fit would be negative is
   * dropped from τ and the others refitted; an edge dropped by all its tetrahedra keeps
   * a token 1e-6 of the stiffest spring. Same order and rest lengths as
   * compute_springs().
   */
  SpringSet
  compute_fitted_springs(const mesh::TetMesh               &mesh,
                         const dealii::Function<3, double> &youngs_modulus,
                         double                             poisson_ratio);
} // namespace lacerta::physics
