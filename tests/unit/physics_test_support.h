// Helpers shared by the physics unit tests: small meshes and particle systems.
#pragma once

#include <lacerta/mesh/tet_mesh.h>
#include <lacerta/mesh/triangulation_conversion.h>
#include <lacerta/physics/assembly.h>
#include <lacerta/physics/force_model.h>
#include <lacerta/physics/particle_system.h>
#include <lacerta/physics/stability.h>

#include <deal.II/base/function.h>
#include <deal.II/grid/grid_generator.h>
#include <deal.II/grid/grid_tools.h>
#include <deal.II/grid/tria.h>

#include <Eigen/Dense>

#include <deque>
#include <memory>
#include <string>
#include <vector>

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


  /**
   * A particle system on @p mesh with constant density and Young's modulus, force model
   * @p model with Poisson ratio @p poisson_ratio. The system refers to @p mesh, which
   * must outlive it.
   */
  inline std::unique_ptr<physics::ParticleSystem>
  make_system(const mesh::TetMesh &mesh,
              const double         density,
              const double         youngs,
              const unsigned int   n_threads     = 1,
              const std::string   &model         = "linear springs",
              const double         poisson_ratio = 0.25)
  {
    // The moduli the systems refer to, for the whole test program.
    static std::deque<dealii::Functions::ConstantFunction<3>> moduli;
    moduli.emplace_back(youngs);
    std::vector<double> rest(3 * mesh.n_vertices());
    for (unsigned int v = 0; v < mesh.n_vertices(); ++v)
      for (unsigned int d = 0; d < 3; ++d)
        rest[3 * v + d] = mesh.vertex(v)[d];
    auto system = std::make_unique<physics::ParticleSystem>(rest);
    system->mass =
      physics::compute_masses(mesh, dealii::Functions::ConstantFunction<3>(density));
    system->springs =
      physics::compute_springs(mesh, dealii::Functions::ConstantFunction<3>(youngs));
    system->mesh           = &mesh;
    system->youngs_modulus = &moduli.back();
    system->poisson_ratio  = poisson_ratio;
    system->set_force_model(physics::ForceModelRegistry::create(model), n_threads);
    return system;
  }


  /// The row Gershgorin bound of M⁻¹K at rest at every free particle,
  /// (λ_max(Σ_e K_e) + Σ_e ||K_e||) / m_i (0 at a constrained particle), the bound
  /// physics::MassBalancer keeps under its target.
  inline std::vector<double>
  rest_row_bounds(const physics::ParticleSystem &system)
  {
    const physics::GershgorinTerms terms =
      physics::gershgorin_terms(system, system.rest_position().data());
    std::vector<double> row = terms.diagonal;
    for (std::size_t s = 0; s < system.springs.size(); ++s)
    {
      row[system.springs.a[s]] += terms.coupling[s];
      row[system.springs.b[s]] += terms.coupling[s];
    }
    for (unsigned int i = 0; i < system.n_particles(); ++i)
      row[i] = system.free[i] > 0 ? row[i] / system.mass[i] : 0.0;
    return row;
  }
  /**
   * The true highest angular eigenfrequency of M⁻¹K at the current positions, from the
   * dense tangent stiffness (with the geometric term) of the free particles'
   * springs.
   */
  inline double
  true_highest_frequency(const physics::ParticleSystem &system)
  {
    const unsigned int n = system.n_particles();
    Eigen::MatrixXd    k = Eigen::MatrixXd::Zero(3 * n, 3 * n);
    const auto        &x = system.position;
    for (std::size_t s = 0; s < system.springs.size(); ++s)
    {
      const unsigned int i = system.springs.a[s], j = system.springs.b[s];
      Eigen::Vector3d    d(x[3 * j] - x[3 * i],
                        x[3 * j + 1] - x[3 * i + 1],
                        x[3 * j + 2] - x[3 * i + 2]);
      const double       length = d.norm();
      d /= length;
      const double    ks = system.springs.stiffness[s];
      const double    g  = ks * (1 - system.springs.rest_length[s] / length);
      Eigen::Matrix3d block =
        (ks - g) * d * d.transpose() + g * Eigen::Matrix3d::Identity();
      k.block<3, 3>(3 * i, 3 * i) += block;
      k.block<3, 3>(3 * j, 3 * j) += block;
      k.block<3, 3>(3 * i, 3 * j) -= block;
      k.block<3, 3>(3 * j, 3 * i) -= block;
    }
    std::vector<unsigned int> free_dofs;
    for (unsigned int i = 0; i < n; ++i)
      if (system.free[i] > 0)
        for (unsigned int d = 0; d < 3; ++d)
          free_dofs.push_back(3 * i + d);
    Eigen::MatrixXd a(free_dofs.size(), free_dofs.size());
    for (std::size_t r = 0; r < free_dofs.size(); ++r)
      for (std::size_t c = 0; c < free_dofs.size(); ++c)
        a(r, c) =
          k(free_dofs[r], free_dofs[c])
          / std::sqrt(system.mass[free_dofs[r] / 3] * system.mass[free_dofs[c] / 3]);
    const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eigen(a, Eigen::EigenvaluesOnly);
    return std::sqrt(eigen.eigenvalues().maxCoeff());
  }


} // namespace lacerta::test_support
