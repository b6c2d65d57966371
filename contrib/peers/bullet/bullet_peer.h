/**
 * @file
 * The Bullet peer's solve: a Lacerta scene (its tetrahedra, lumped masses, fixed
 * particles, gravity, E and ν) as a Bullet 3.24 deformable body with the implicit
 * corotated linear FEM force, stepped until it settles.
 *
 * Bullet's headers and deal.II's (through Trilinos' Epetra) both declare a global
 * `Add`, so no translation unit includes both: bullet_solve.cc sees Bullet and this
 * header only, scene_input.cc and main.cc see Lacerta.
 */
#pragma once

#include <array>
#include <vector>

namespace lacerta::scene
{
  class Scene;
}

namespace lacerta::peers::bullet
{
  /**
   * The body as Bullet gets it, in plain arrays.
   */
  struct BulletInput
  {
    /// Rest positions, 3 per node (node i is the scene's vertex and particle i).
    std::vector<double> rest_position;
    /// The tetrahedra, vertex ids.
    std::vector<std::array<unsigned int, 4>> tets;
    /// The edges of the tetrahedra (Bullet's links), vertex ids.
    std::vector<std::array<unsigned int, 2>> edges;
    /// Lumped masses (kg); zero for a fixed node (zero inverse mass in Bullet).
    std::vector<double> mass;
    /// Uniform body acceleration (m/s²).
    std::array<double, 3> gravity = {{0, 0, 0}};
    /// Young's modulus (Pa) and Poisson ratio of the whole body.
    double youngs_modulus = 0, poisson_ratio = 0;
    /// The scene's mass damping (1/s), the default of BulletSettings::mass_damping.
    double mass_damping = 0;
  };


  /**
   * The BulletInput of @p scene's active mesh with its particle system as assembled
   * and loaded: masses, prescribed particles as fixed nodes, body acceleration, E and
   * ν. What Bullet cannot represent (E varying in space, a particle prescribed away
   * from its rest position, point forces) is an Error.
   */
  BulletInput
  input_from_scene(const scene::Scene &scene);

  /**
   * How the Bullet body is stepped to its static state.
   */
  struct BulletSettings
  {
    /// Implicit (backward Euler) time step (s).
    double time_step = 1e-2;
    /// Mass-proportional damping of btDeformableLinearElasticityForce (1/s); negative:
    /// the scene's `Material/Mass damping`.
    double mass_damping = -1;
    /// Stiffness-proportional damping of the same force (s).
    double stiffness_damping = 0;
    /// The state has settled when no node moved more than this fraction of the largest
    /// displacement in the last step.
    double settle_tolerance = 1e-8;
    /// Steps before the run stops unsettled.
    unsigned int max_steps = 20000;
  };


  /**
   * What the Bullet run gave.
   */
  struct BulletResult
  {
    /// Displacement of every vertex, 3 per vertex (Bullet node i is Lacerta vertex i).
    std::vector<double> displacement;
    /// Wall time of the stepping loop (s): the solve, not the building of the body.
    double wall_time = 0;
    /// Steps taken.
    unsigned int steps = 0;
    /// Whether the settle tolerance was met within the step budget.
    bool settled = false;
    /// The largest node motion of the last step over the largest displacement.
    double last_change = 0;
  };


  /**
   * Builds a btSoftBody of @p input (nodes at rest with their masses, fixed nodes with
   * zero inverse mass, tetrahedra positively oriented, a link per edge, boundary
   * faces), adds btDeformableLinearElasticityForce (corotated linear elasticity with
   * the Lamé parameters of E and ν, and the settings' damping) and
   * btDeformableGravityForce to a btDeformableMultiBodyDynamicsWorld with the implicit
   * btDeformableBodySolver, and steps from rest until the state settles or the step
   * budget is spent. A state that stops being finite is an Error.
   */
  BulletResult
  solve_with_bullet(const BulletInput &input, const BulletSettings &settings);
} // namespace lacerta::peers::bullet
