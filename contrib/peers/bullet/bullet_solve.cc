#include <lacerta/base/exceptions.h>

#include "bullet_peer.h"
#include <BulletCollision/BroadphaseCollision/btDbvtBroadphase.h>
#include <BulletSoftBody/btDeformableBodySolver.h>
#include <BulletSoftBody/btDeformableGravityForce.h>
#include <BulletSoftBody/btDeformableLinearElasticityForce.h>
#include <BulletSoftBody/btDeformableMultiBodyConstraintSolver.h>
#include <BulletSoftBody/btDeformableMultiBodyDynamicsWorld.h>
#include <BulletSoftBody/btSoftBody.h>
#include <BulletSoftBody/btSoftBodyHelpers.h>
#include <BulletSoftBody/btSoftBodyRigidBodyCollisionConfiguration.h>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <memory>

namespace lacerta::peers::bullet
{
  namespace
  {
    /**
     * Bullet's objects for one deformable body, owned in the order they depend on
     * each other; the body is taken out of the world before either goes.
     */
    class BulletWorld
    {
    public:
      explicit BulletWorld(const btVector3 &gravity)
          : dispatcher(&configuration)
          , world(&dispatcher, &broadphase, &constraint_solver, &configuration, &solver)
      {
        constraint_solver.setDeformableSolver(&solver);
        world.setImplicit(true);
        world.setLineSearch(false);
        // Bullet 3.24's default (Lagrange multipliers, conjugate residual) leaves every
        // node at rest in implicit mode, even a free-falling tetrahedron; with
        // projection the Newton steps solve by conjugate gradients and move the body.
        world.setUseProjection(true);
        world.setGravity(gravity);
        world.getWorldInfo().m_gravity = gravity;
      }

      ~BulletWorld()
      {
        if (body)
          world.removeSoftBody(body.get());
      }

      BulletWorld(const BulletWorld &) = delete;
      BulletWorld &
      operator=(const BulletWorld &) = delete;

      btSoftBodyRigidBodyCollisionConfiguration          configuration;
      btCollisionDispatcher                              dispatcher;
      btDbvtBroadphase                                   broadphase;
      btDeformableBodySolver                             solver;
      btDeformableMultiBodyConstraintSolver              constraint_solver;
      btDeformableMultiBodyDynamicsWorld                 world;
      std::unique_ptr<btDeformableLinearElasticityForce> elasticity;
      std::unique_ptr<btDeformableGravityForce>          gravity_force;
      std::unique_ptr<btSoftBody>                        body;
    };


    /**
     * The soft body of @p input: nodes at rest with their masses (zero inverse mass for
     * a fixed node), tetrahedra positively oriented, a link per edge and the boundary
     * faces, with the rest shapes Bullet's forces need.
     */
    std::unique_ptr<btSoftBody>
    make_soft_body(btSoftBodyWorldInfo &info, const BulletInput &input)
    {
      const std::size_t      n = input.mass.size();
      std::vector<btVector3> nodes;
      for (std::size_t i = 0; i < n; ++i)
        nodes.emplace_back(input.rest_position[3 * i],
                           input.rest_position[3 * i + 1],
                           input.rest_position[3 * i + 2]);
      auto body =
        std::make_unique<btSoftBody>(&info, static_cast<int>(n), nodes.data(), nullptr);
      for (std::size_t i = 0; i < n; ++i)
        body->setMass(static_cast<int>(i), input.mass[i]);
      for (auto tet : input.tets)
      {
        const btVector3 a = nodes[tet[1]] - nodes[tet[0]],
                        b = nodes[tet[2]] - nodes[tet[0]],
                        c = nodes[tet[3]] - nodes[tet[0]];
        // Bullet takes the element measure as det(Dm) / 6, signed.
        if (a.dot(b.cross(c)) < 0)
          std::swap(tet[2], tet[3]);
        body->appendTetra(tet[0], tet[1], tet[2], tet[3]);
      }
      for (const auto &edge : input.edges)
        body->appendLink(edge[0], edge[1]);
      btSoftBodyHelpers::generateBoundaryFaces(body.get());
      body->initializeDmInverse();
      body->m_tetraScratches.resize(body->m_tetras.size());
      body->m_tetraScratchesTn.resize(body->m_tetras.size());
      body->setSelfCollision(false);
      // A body that falls asleep stops feeling its forces before it has settled.
      body->setActivationState(DISABLE_DEACTIVATION);
      return body;
    }


    /// Adds the corotated linear elasticity and gravity forces of @p input.
    void
    add_forces(BulletWorld          &bullet,
               const BulletInput    &input,
               const BulletSettings &settings)
    {
      const double e = input.youngs_modulus, nu = input.poisson_ratio;
      const double mu = e / (2 * (1 + nu)), lambda = e * nu / ((1 + nu) * (1 - 2 * nu));
      const double alpha =
        settings.mass_damping < 0 ? input.mass_damping : settings.mass_damping;
      bullet.elasticity = std::make_unique<btDeformableLinearElasticityForce>(
        mu, lambda, alpha, settings.stiffness_damping);
      const auto &g = input.gravity;
      bullet.gravity_force =
        std::make_unique<btDeformableGravityForce>(btVector3(g[0], g[1], g[2]));
      bullet.world.addForce(bullet.body.get(), bullet.elasticity.get());
      bullet.world.addForce(bullet.body.get(), bullet.gravity_force.get());
    }


    /// Steps @p bullet until its body settles or the budget is spent (timed).
    BulletResult
    step_until_settled(BulletWorld &bullet, const BulletSettings &settings)
    {
      btSoftBody         &body = *bullet.body;
      const int           n    = body.m_nodes.size();
      std::vector<double> rest(3 * n), previous(3 * n);
      for (int i = 0; i < n; ++i)
        for (int d = 0; d < 3; ++d)
          rest[3 * i + d] = previous[3 * i + d] = body.m_nodes[i].m_x[d];

      BulletResult result;
      const auto   start = std::chrono::steady_clock::now();
      while (result.steps < settings.max_steps && !result.settled)
      {
        bullet.world.stepSimulation(settings.time_step, 0);
        ++result.steps;
        double largest = 0, change = 0;
        for (int i = 0; i < n; ++i)
        {
          double u2 = 0, du2 = 0;
          for (int d = 0; d < 3; ++d)
          {
            const double x = body.m_nodes[i].m_x[d];
            u2 += (x - rest[3 * i + d]) * (x - rest[3 * i + d]);
            du2 += (x - previous[3 * i + d]) * (x - previous[3 * i + d]);
            previous[3 * i + d] = x;
          }
          largest = std::max(largest, u2);
          change  = std::max(change, du2);
        }
        if (!std::isfinite(largest))
          throw_error("Bullet peer: the Bullet state is not finite after step ",
                      result.steps,
                      " (time step ",
                      settings.time_step,
                      " s).");
        result.last_change = largest > 0 ? std::sqrt(change / largest) : 0;
        result.settled = largest > 0 && result.last_change < settings.settle_tolerance;
      }
      result.wall_time =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      result.displacement.resize(3 * n);
      for (int k = 0; k < 3 * n; ++k)
        result.displacement[k] = previous[k] - rest[k];
      return result;
    }
  } // namespace


  BulletResult
  solve_with_bullet(const BulletInput &input, const BulletSettings &settings)
  {
    if (!(settings.time_step > 0))
      throw_error("Bullet peer: the time step must be positive (it is ",
                  settings.time_step,
                  " s).");
    if (!(input.youngs_modulus > 0) || !(input.poisson_ratio >= 0)
        || !(input.poisson_ratio < 0.5))
      throw_error("Bullet peer: needs E > 0 and 0 <= nu < 0.5 (E = ",
                  input.youngs_modulus,
                  " Pa, nu = ",
                  input.poisson_ratio,
                  ").");
    const auto &g = input.gravity;
    BulletWorld bullet(btVector3(g[0], g[1], g[2]));
    bullet.body = make_soft_body(bullet.world.getWorldInfo(), input);
    bullet.world.addSoftBody(bullet.body.get());
    add_forces(bullet, input, settings);
    return step_until_settled(bullet, settings);
  }
} // namespace lacerta::peers::bullet
