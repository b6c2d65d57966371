/**
 * @file
 * The FEM reference's Problem for a scene: the same mesh, material, constraints and
 * loads as the scene's spring model.
 */
#pragma once

#include <lacerta/fem/elasticity.h>

namespace lacerta::physics
{
  class ParticleSystem;
}
namespace lacerta::scene
{
  class Material;
  class Scene;
} // namespace lacerta::scene

namespace lacerta::fem
{
  /**
   * The Problem of @p scene: its mesh and material; the particles its constraints
   * prescribe, moved as they prescribe; its uniform body acceleration; and the point
   * forces its force handles and varying body forces put on the particles (evaluated
   * through Scene::update_loads, so asking for them changes the spring system's
   * external forces to those of the same time). @p scene must outlive the Problem.
   */
  Problem
  problem_from_scene(scene::Scene &scene);

  /**
   * The Problem of a running particle system: as problem_from_scene(), but the point
   * forces are the system's current external forces (whoever runs the system updates
   * them). @p mesh, @p material and @p system must outlive the Problem.
   */
  Problem
  problem_from_system(const mesh::TetMesh           &mesh,
                      const scene::Material         &material,
                      const physics::ParticleSystem &system);
} // namespace lacerta::fem
