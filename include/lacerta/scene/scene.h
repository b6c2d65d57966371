/**
 * @file
 * A scene: the object (mesh, material), its particle system, constraints and loads.
 */
#pragma once

#include <lacerta/mesh/tet_mesh.h>
#include <lacerta/scene/body_force.h>
#include <lacerta/scene/constraint.h>
#include <lacerta/scene/material.h>

#include <memory>
#include <ostream>
#include <vector>

namespace lacerta::physics
{
  class ParticleSystem;
}

namespace lacerta::cut
{
  class Tool;
  class Cutter;
} // namespace lacerta::cut

namespace lacerta::scene
{
  /**
   * Builds and owns what a parameter file describes: the mesh (numbered spatially), the
   * material, the particle system with its masses (3.1) and springs (3.2), the
   * constraints and the body forces.
   */
  class Scene
  {
  public:
    /**
     * Declares the scene's subsections (Mesh, Material, Force model, Body forces,
     * Constraints with the given instance names).
     */
    static void
    declare_parameters(dealii::ParameterHandler       &prm,
                       const std::vector<std::string> &constraint_names);

    /**
     * Builds everything from @p prm; the force evaluation runs on @p n_threads threads.
     * Bad input is a lacerta::Error naming the entry, file, element or particle.
     */
    Scene(dealii::ParameterHandler &prm, unsigned int n_threads);

    ~Scene();

    /// Recomputes the external forces at time @p t (only if some load varies).
    void
    update_loads(double t);

    /// Writes a description of the scene (sizes, mass, stiffness range, constraints).
    void
    print_summary(std::ostream &out) const;

    /// The mesh in its rest configuration.
    mesh::TetMesh mesh;
    /// The material fields.
    Material material;
    /// The particle system.
    std::unique_ptr<physics::ParticleSystem> system;
    /// The constraints, in the order of `Constraints/Names`.
    std::vector<std::unique_ptr<Constraint>> constraints;
    /// The body forces.
    std::vector<std::unique_ptr<BodyForce>> body_forces;
    /// ∫σ over the mesh, with the rule of the mass assembly (kept up to date by cuts).
    double integral_of_density = 0;
    /// Volume of the mesh as built (cuts conserve it).
    double initial_volume = 0;
    /// The cutting tool and the cutter, only if `Tool/Type` is not `none`.
    std::unique_ptr<cut::Tool>   tool;
    std::unique_ptr<cut::Cutter> cutter;

  private:
    bool has_varying_loads = false;
  };
} // namespace lacerta::scene
