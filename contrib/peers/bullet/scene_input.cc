#include <lacerta/base/exceptions.h>
#include <lacerta/mesh/tet_mesh.h>
#include <lacerta/physics/particle_system.h>
#include <lacerta/scene/scene.h>

#include <deal.II/base/point.h>

#include "bullet_peer.h"
#include <cmath>

namespace lacerta::peers::bullet
{
  namespace
  {
    /// The one Young's modulus of @p scene, or an Error if it varies over the mesh.
    double
    uniform_youngs_modulus(const scene::Scene &scene)
    {
      const mesh::TetMesh &mesh = scene.active_mesh();
      const auto          &x    = mesh.get_vertices();
      double               e0   = 0;
      for (unsigned int t = 0; t < mesh.n_tets(); ++t)
      {
        dealii::Point<3> centroid;
        for (const unsigned int v : mesh.tet(t))
          for (unsigned int d = 0; d < 3; ++d)
            centroid[d] += 0.25 * x[v][d];
        const double e = scene.material.youngs_modulus().value(centroid);
        if (t == 0)
          e0 = e;
        else if (std::abs(e - e0) > 1e-12 * std::abs(e0))
          throw_error("Bullet peer: btDeformableLinearElasticityForce has one Young's "
                      "modulus per body, but 'Material/Youngs modulus' varies (",
                      e0,
                      " Pa and ",
                      e,
                      " Pa).");
      }
      return e0;
    }
  } // namespace


  BulletInput
  input_from_scene(const scene::Scene &scene)
  {
    const mesh::TetMesh           &mesh   = scene.active_mesh();
    const physics::ParticleSystem &system = *scene.system;
    BulletInput                    input;
    input.rest_position = system.rest_position();
    input.mass          = system.mass;
    for (unsigned int i = 0; i < system.n_particles(); ++i)
    {
      for (unsigned int d = 0; d < 3; ++d)
      {
        if (system.free[i] == 0
            && system.position[3 * i + d] != system.rest_position()[3 * i + d])
          throw_error("Bullet peer: particle ",
                      i,
                      " is prescribed away from its rest position; only fixed "
                      "constraints are modelled (as zero inverse mass).");
        if (system.external_force[3 * i + d] != 0)
          throw_error("Bullet peer: particle ",
                      i,
                      " carries a point force; only gravity is modelled.");
      }
      if (system.free[i] == 0)
        input.mass[i] = 0;
    }
    input.tets           = mesh.get_tets();
    input.edges          = mesh.get_edges();
    input.gravity        = system.body_acceleration;
    input.youngs_modulus = uniform_youngs_modulus(scene);
    input.poisson_ratio  = scene.material.poisson_ratio;
    input.mass_damping   = system.mass_damping;
    return input;
  }
} // namespace lacerta::peers::bullet
