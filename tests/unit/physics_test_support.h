// Helpers shared by the physics unit tests: small meshes and particle systems.
#pragma once

#include <lacerta/mesh/tet_mesh.h>
#include <lacerta/mesh/triangulation_conversion.h>
#include <lacerta/physics/assembly.h>
#include <lacerta/physics/force_model.h>
#include <lacerta/physics/particle_system.h>

#include <deal.II/base/function.h>
#include <deal.II/grid/grid_generator.h>
#include <deal.II/grid/grid_tools.h>
#include <deal.II/grid/tria.h>

#include <memory>

namespace lacerta::test_support
{
  /// A box of n x n x n hexahedra split into tetrahedra, interior vertices moved
  /// randomly.
  inline mesh::TetMesh
  distorted_box(const unsigned int      n,
                const double            distortion,
                const dealii::Point<3> &upper)
  {
    dealii::Triangulation<3> tria;
    dealii::GridGenerator::subdivided_hyper_rectangle_with_simplices(tria,
                                                                     {n, n, n},
                                                                     dealii::Point<3>(),
                                                                     upper);
    if (distortion > 0)
      dealii::GridTools::distort_random(distortion, tria, true, 42);
    return mesh::tet_mesh_from_triangulation(tria, "distorted box");
  }


  /// A particle system on @p mesh with constant density and Young's modulus.
  inline std::unique_ptr<physics::ParticleSystem>
  make_system(const mesh::TetMesh &mesh,
              const double         density,
              const double         youngs,
              const unsigned int   n_threads = 1)
  {
    std::vector<double> rest(3 * mesh.n_vertices());
    for (unsigned int v = 0; v < mesh.n_vertices(); ++v)
      for (unsigned int d = 0; d < 3; ++d)
        rest[3 * v + d] = mesh.vertex(v)[d];
    auto system = std::make_unique<physics::ParticleSystem>(rest);
    system->mass =
      physics::compute_masses(mesh, dealii::Functions::ConstantFunction<3>(density));
    system->springs =
      physics::compute_springs(mesh, dealii::Functions::ConstantFunction<3>(youngs));
    system->enforce_constraints = [](double, double *, double *) {};
    system->set_force_model(physics::ForceModelRegistry::create("linear springs"),
                            n_threads);
    return system;
  }
} // namespace lacerta::test_support
