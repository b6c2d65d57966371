#include <lacerta/fem/scene_problem.h>
#include <lacerta/physics/particle_system.h>
#include <lacerta/scene/scene.h>

namespace lacerta::fem
{
  Problem
  problem_from_system(const mesh::TetMesh           &mesh,
                      const scene::Material         &material,
                      const physics::ParticleSystem &system)
  {
    Problem problem;
    problem.mesh              = &mesh;
    problem.density           = &material.density();
    problem.youngs_modulus    = &material.youngs_modulus();
    problem.poisson_ratio     = material.poisson_ratio;
    problem.mass_damping      = material.mass_damping;
    problem.stiffness_damping = material.spring_damping;
    problem.body_acceleration = system.body_acceleration;
    problem.prescribed.resize(system.n_particles());
    for (unsigned int i = 0; i < system.n_particles(); ++i)
      problem.prescribed[i] = system.free[i] == 0;
    // The buffers live in the callback, which a Newmark run calls every step.
    problem.displacement =
      [&system,
       x = std::vector<double>(),
       v = std::vector<double>()](const double t, std::vector<double> &u) mutable
    {
      x = system.rest_position();
      v.assign(x.size(), 0.0);
      system.enforce_constraints(t, x.data(), v.data());
      for (std::size_t k = 0; k < x.size(); ++k)
        u[k] = x[k] - system.rest_position()[k];
    };
    problem.point_forces = [&system](double, std::vector<double> &f)
    { f = system.external_force; };
    return problem;
  }


  Problem
  problem_from_scene(scene::Scene &scene)
  {
    Problem problem      = problem_from_system(scene.mesh, scene.material, *scene.system);
    problem.point_forces = [&scene](const double t, std::vector<double> &f)
    {
      scene.update_loads(t);
      f = scene.system->external_force;
    };
    return problem;
  }
} // namespace lacerta::fem
