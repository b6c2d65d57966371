// Helpers shared by the benchmarks.
#pragma once

#include <lacerta/mesh/tet_mesh.h>
#include <lacerta/physics/assembly.h>
#include <lacerta/physics/force_model.h>
#include <lacerta/physics/particle_system.h>

#include <deal.II/base/function.h>

#include <memory>
#include <vector>

namespace lacerta::bench
{
  /// A particle system at rest on @p mesh, with masses and linear springs from
  /// @p density and @p youngs, no constraints, one thread.
  inline std::unique_ptr<physics::ParticleSystem>
  make_particle_system(const mesh::TetMesh               &mesh,
                       const dealii::Function<3, double> &density,
                       const dealii::Function<3, double> &youngs)
  {
    std::vector<double> rest(3 * mesh.n_vertices());
    for (unsigned int v = 0; v < mesh.n_vertices(); ++v)
      for (unsigned int d = 0; d < 3; ++d)
        rest[3 * v + d] = mesh.vertex(v)[d];
    auto system     = std::make_unique<physics::ParticleSystem>(rest);
    system->mass    = physics::compute_masses(mesh, density);
    system->springs = physics::compute_springs(mesh, youngs);
    system->set_force_model(physics::ForceModelRegistry::create("linear springs"), 1);
    return system;
  }
} // namespace lacerta::bench
