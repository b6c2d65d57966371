/**
 * @file
 * The particle system's parameters from the mesh and the materials (Sections 3.1, 3.2).
 */
#pragma once

#include <lacerta/mesh/tet_mesh.h>
#include <lacerta/physics/spring_set.h>

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
  SpringSet
  compute_springs(const mesh::TetMesh               &mesh,
                  const dealii::Function<3, double> &youngs_modulus);
} // namespace lacerta::physics
