// The force models per tetrahedron, `volume springs` and `corotated fem`: forces are
// minus the gradient of their energy, vanish at rest and under rigid motions, give the
// asked Poisson ratio in a pulled bar, are stable below their bound, and follow cuts.

#include <lacerta/cut/tool.h>
#include <lacerta/physics/integrator.h>
#include <lacerta/physics/stability.h>
#include <lacerta/physics/volume_spring_parameters.h>

#include <Eigen/Dense>
#include <gtest/gtest.h>

#include "mt_test_support.h"
#include "physics_test_support.h"
#include "pulled_bar.h"
#include <cmath>
#include <iostream>
#include <random>
#include <sstream>

using namespace lacerta;

namespace
{
  const std::vector<std::string> element_models = {"volume springs", "corotated fem"};

  /// A box of 2 x 2 x 2 cells, 0.1 m wide, interior vertices moved.
  mesh::TetMesh
  small_mesh()
  {
    return test_support::distorted_box(2, 0.2, dealii::Point<3>(0.1, 0.1, 0.1));
  }


  /// @p x moved randomly by up to @p amplitude in every coordinate.
  std::vector<double>
  perturbed(std::vector<double> x, const double amplitude, const unsigned int seed)
  {
    std::mt19937                           random(seed);
    std::uniform_real_distribution<double> uniform(-amplitude, amplitude);
    for (double &c : x)
      c += uniform(random);
    return x;
  }


  /// The elastic forces of @p system's model at @p x (no velocities).
  std::vector<double>
  forces_at(const physics::ParticleSystem &system, const std::vector<double> &x)
  {
    std::vector<double> v(x.size(), 0.0), f(x.size());
    system.force_model().compute_spring_forces(system, x.data(), v.data(), f.data());
    return f;
  }


  double
  largest_magnitude(const std::vector<double> &values)
  {
    double largest = 0;
    for (const double v : values)
      largest = std::max(largest, std::abs(v));
    return largest;
  }


  /// @p x rotated by a rotation about (1, 2, 3) by 0.7 rad and shifted.
  std::vector<double>
  rigidly_moved(const std::vector<double> &x)
  {
    const Eigen::Matrix3d R =
      Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
    std::vector<double> y(x.size());
    for (std::size_t i = 0; i < x.size() / 3; ++i)
    {
      const Eigen::Vector3d p = R * Eigen::Vector3d(x[3 * i], x[3 * i + 1], x[3 * i + 2]);
      for (unsigned int d = 0; d < 3; ++d)
        y[3 * i + d] = p[d] + 0.05 * (d + 1);
    }
    return y;
  }


  /**
   * -∂f/∂x of @p system's model at @p x over the free degrees of freedom @p dofs, by
   * central differences.
   */
  Eigen::MatrixXd
  tangent_stiffness(const physics::ParticleSystem   &system,
                    std::vector<double>              x,
                    const std::vector<unsigned int> &dofs,
                    const double                     h)
  {
    Eigen::MatrixXd k(dofs.size(), dofs.size());
    for (std::size_t c = 0; c < dofs.size(); ++c)
    {
      const double saved = x[dofs[c]];
      x[dofs[c]]         = saved + h;
      const auto plus    = forces_at(system, x);
      x[dofs[c]]         = saved - h;
      const auto minus   = forces_at(system, x);
      x[dofs[c]]         = saved;
      for (std::size_t r = 0; r < dofs.size(); ++r)
        k(r, c) = -(plus[dofs[r]] - minus[dofs[r]]) / (2 * h);
    }
    return k;
  }


  /// The degrees of freedom of the free particles.
  std::vector<unsigned int>
  free_dofs(const physics::ParticleSystem &system)
  {
    std::vector<unsigned int> dofs;
    for (unsigned int i = 0; i < system.n_particles(); ++i)
      if (system.free[i] > 0)
        for (unsigned int d = 0; d < 3; ++d)
          dofs.push_back(3 * i + d);
    return dofs;
  }


  /**
   * The displacements of @p system's static equilibrium under its external forces,
   * by Newton's method on the model's own forces with a finite-difference tangent.
   */
  std::vector<double>
  static_displacement(const physics::ParticleSystem &system)
  {
    const std::vector<unsigned int> dofs = free_dofs(system);
    std::vector<double>             x    = system.position;
    const double                    h    = 1e-7;
    for (unsigned int iteration = 0; iteration < 6; ++iteration)
    {
      const auto      f = forces_at(system, x);
      Eigen::VectorXd residual(dofs.size());
      for (std::size_t r = 0; r < dofs.size(); ++r)
        residual[r] = f[dofs[r]] + system.external_force[dofs[r]];
      const Eigen::VectorXd step =
        tangent_stiffness(system, x, dofs, h).partialPivLu().solve(residual);
      for (std::size_t r = 0; r < dofs.size(); ++r)
        x[dofs[r]] += step[r];
      if (step.lpNorm<Eigen::Infinity>() < 1e-13)
        break;
    }
    std::vector<double> u(x.size());
    for (std::size_t c = 0; c < x.size(); ++c)
      u[c] = x[c] - system.rest_position()[c];
    return u;
  }
} // namespace


TEST(ElementModels, ForcesAreMinusTheGradientOfTheEnergy)
{
  const mesh::TetMesh mesh = small_mesh();
  for (const std::string &model : element_models)
    for (const double nu : {0.0, 0.3, 0.49})
    {
      auto system           = test_support::make_system(mesh, 1000, 1e5, 1, model, nu);
      std::vector<double> x = perturbed(system->position, 0.01, 11);
      const auto          f = forces_at(*system, x);
      double              largest_error = 0;
      const double        h             = 1e-6;
      for (std::size_t c = 0; c < x.size(); ++c)
      {
        const double saved = x[c];
        x[c]               = saved + h;
        const double plus  = system->force_model().elastic_energy(*system, x.data());
        x[c]               = saved - h;
        const double minus = system->force_model().elastic_energy(*system, x.data());
        x[c]               = saved;
        largest_error =
          std::max(largest_error, std::abs(f[c] + (plus - minus) / (2 * h)));
      }
      EXPECT_LT(largest_error, 1e-6 * largest_magnitude(f)) << model << ", nu " << nu;
      EXPECT_GT(system->force_model().elastic_energy(*system, x.data()), 0) << model;
    }
}


TEST(ElementModels, NoForceAtRestNorUnderRigidMotions)
{
  const mesh::TetMesh mesh = small_mesh();
  for (const std::string &model : element_models)
  {
    auto         system = test_support::make_system(mesh, 1000, 1e5, 1, model, 0.45);
    const double scale =
      largest_magnitude(forces_at(*system, perturbed(system->rest_position(), 1e-3, 5)));
    EXPECT_LT(largest_magnitude(forces_at(*system, system->rest_position())),
              1e-10 * scale)
      << model;
    EXPECT_LT(largest_magnitude(
                forces_at(*system, rigidly_moved(system->rest_position()))),
              1e-9 * scale)
      << model;
    EXPECT_LT(system->force_model().elastic_energy(
                *system, rigidly_moved(system->rest_position()).data()),
              1e-20)
      << model;
  }
}


TEST(ElementModels, BoundIsAboveTheTrueFrequencyAndStableAtNinetyPercent)
{
  const mesh::TetMesh mesh = small_mesh();
  for (const std::string &model : element_models)
    for (const double nu : {0.0, 0.25, 0.49})
    {
      auto system      = test_support::make_system(mesh, 1000, 1e5, 1, model, nu);
      system->position = perturbed(system->rest_position(), 2e-3, 3);
      const std::vector<unsigned int> dofs = free_dofs(*system);
      const Eigen::MatrixXd k = tangent_stiffness(*system, system->position, dofs, 1e-8);
      Eigen::MatrixXd       a(dofs.size(), dofs.size());
      for (std::size_t r = 0; r < dofs.size(); ++r)
        for (std::size_t c = 0; c < dofs.size(); ++c)
          a(r, c) = 0.5 * (k(r, c) + k(c, r))
                    / std::sqrt(system->mass[dofs[r] / 3] * system->mass[dofs[c] / 3]);
      const double true_omega = std::sqrt(
        Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(a, Eigen::EigenvaluesOnly)
          .eigenvalues()
          .maxCoeff());
      const double bound = physics::bound_highest_frequency(*system).omega;
      EXPECT_TRUE(std::isfinite(bound) && bound > 0) << model;
      EXPECT_GE(bound, true_omega * (1 - 1e-6)) << model << ", nu " << nu;
      EXPECT_LE(bound, 3.0 * true_omega) << model << ", nu " << nu;
      std::cout << model << ", nu " << nu << ": bound " << bound << " rad/s, true "
                << true_omega << " rad/s\n";

      for (const std::string name : {"symplectic_euler", "velocity_verlet", "rk4"})
      {
        auto run              = test_support::make_system(mesh, 1000, 1e5, 1, model, nu);
        run->position         = perturbed(run->rest_position(), 2e-3, 3);
        const auto integrator = physics::IntegratorRegistry::create(name);
        integrator->initialize(*run);
        double                 dt = 0.9 * integrator->critical_time_step(bound, 0, 0);
        physics::BlowUpMonitor monitor(*run, 1.0);
        // The largest energy over the first and the last 1000 steps: an unstable mode
        // grows geometrically, so the last would be far above the first. The energy
        // itself is not compared with the initial one: symplectic Euler keeps a
        // modified energy, and the one measured swings by up to 1 / (1 - (ω dt / 2)²)
        // around it, a factor 5 at 0.9 times the limit.
        double first = 0, last = 0, time = 0;
        for (unsigned int step = 1; step <= 3000; ++step)
        {
          time += dt;
          integrator->step(*run, time, dt);
          if (step % 100 == 0)
          {
            EXPECT_NO_THROW(monitor.check(*run, step, time)) << model << ", " << name;
            // As the simulator does at its checks: the frequency of a nonlinear model
            // changes with the deformation (the volume springs' at nu = 0 rose by more
            // than the 1.28 between the bound and the true one at the start, and a
            // step kept from the start blew up after 3,500 steps).
            dt = std::min(dt,
                          0.9
                            * integrator->critical_time_step(
                              physics::bound_highest_frequency(*run).omega, 0, 0));
          }
          const double energy = run->kinetic_energy() + run->elastic_energy();
          if (step <= 1000)
            first = std::max(first, energy);
          else if (step > 2000)
            last = std::max(last, energy);
        }
        EXPECT_TRUE(std::isfinite(last)) << model << ", " << name << ", nu " << nu;
        EXPECT_LT(last, 1.05 * first) << model << ", " << name << ", nu " << nu;
      }
    }
}


TEST(ElementModels, PulledBarContractsWithTheAskedPoissonRatio)
{
  // The volume springs with the lattice ratio of box meshes (0.117, measured by
  // FemAccuracy.PoissonRatioOfFemAndOfSprings): a shear term below it, a volume term
  // above.
  const std::vector<std::pair<std::string, std::vector<double>>> cases = {
    {"volume springs", {0.0, 0.05, 0.15, 0.25, 0.35, 0.45, 0.49}},
    {"corotated fem", {0.0, 0.25, 0.45, 0.49}}};
  for (const auto &[model, ratios] : cases)
  {
    double previous = -1;
    for (const double nu : ratios)
    {
      std::ostringstream text;
      text << nu;
      auto         bar = test_support::pulled_bar(text.str(), "paper", model, "0.117");
      const double measured =
        test_support::effective_poisson_ratio(bar->mesh,
                                              static_displacement(*bar->system));
      std::cout << model << ": asked nu " << nu << ", lateral contraction " << measured
                << "\n";
      EXPECT_GT(measured, previous) << model << ": " << nu;
      previous = measured;
      if (model == "volume springs" && nu < 0.117)
      {
        // Below the lattice's ratio the shear term also stiffens the lattice's
        // non-affine relaxation, which the isotropic derivation does not see: 0.053
        // at 0 and 0.084 at 0.05 measured (doc/physics.md).
        EXPECT_NEAR(measured, nu, 0.06) << model;
      }
      else if (nu <= 0.45)
      {
        EXPECT_NEAR(measured, nu, 0.03) << model;
      }
      else
      {
        // Nearly incompressible: sensible, between the compressible ones and 1/2.
        EXPECT_TRUE(measured > 0.42 && measured < 0.5) << model << ": " << measured;
      }
    }
  }
}


TEST(ElementModels, RunThroughACutAndStayAtRestThere)
{
  // The model follows the cut locally (PartitionedTets::update()), on one range and
  // on two (the new particles join the last range).
  for (const std::string &model : element_models)
    for (const unsigned int threads : {1u, 2u})
    {
      auto scene =
        test_support::slab_cut_scene(model, 0.003, 0.07, 0.003, -0.07, threads);
      physics::ParticleSystem &system = *scene->system;
      const unsigned int       before = scene->mesh.n_tets();
      for (unsigned int k = 1; k <= 20; ++k)
        scene->cut(scene->tool->blade(k / 20.0), 0.01 * k);
      ASSERT_GT(scene->mesh.n_tets(), before) << model;
      ASSERT_EQ(system.n_particles(), scene->mesh.n_vertices()) << model;

      // At rest (the rest positions of every particle, new ones included): no force.
      const double scale =
        largest_magnitude(forces_at(system, perturbed(system.rest_position(), 1e-4, 9)));
      EXPECT_LT(largest_magnitude(forces_at(system, system.rest_position())),
                1e-9 * scale)
        << model;
      // The model after the cut is the model made afresh on the cut mesh.
      auto fresh = physics::ForceModelRegistry::create(model);
      fresh->initialize(system, threads);
      const std::vector<double> x = perturbed(system.position, 1e-3, 4);
      std::vector<double>       v(x.size(), 0.0), theirs(x.size());
      fresh->compute_spring_forces(system, x.data(), v.data(), theirs.data());
      const auto mine = forces_at(system, x);
      for (std::size_t c = 0; c < x.size(); ++c)
        EXPECT_NEAR(mine[c], theirs[c], 1e-12 * largest_magnitude(theirs)) << model;

      // And it runs, below its bound, with the blow-up monitor watching.
      const auto integrator = physics::IntegratorRegistry::create("velocity_verlet");
      integrator->initialize(system);
      const double dt =
        0.9
        * integrator->critical_time_step(physics::bound_highest_frequency(system).omega,
                                         system.mass_damping,
                                         system.spring_damping);
      physics::BlowUpMonitor monitor(system, 1.0);
      for (unsigned int step = 1; step <= 200; ++step)
      {
        integrator->step(system, step * dt, dt);
        EXPECT_NO_THROW(monitor.check(system, step, step * dt)) << model;
      }
    }
}


TEST(ElementModels, BadInputIsAClearError)
{
  const mesh::TetMesh mesh = small_mesh();
  for (const std::string &model : element_models)
  {
    EXPECT_THROW(test_support::make_system(mesh, 1000, 1e5, 1, model, 0.5), Error)
      << model;
    EXPECT_THROW(test_support::make_system(mesh, 1000, 1e5, 1, model, -0.1), Error)
      << model;
    EXPECT_THROW(test_support::make_system(mesh, 1000, -1e5, 1, model), Error) << model;
  }
}


TEST(ElementModels, VolumeSpringParametersGiveTheModuliOfTheDerivation)
{
  // ν = 1/4 is the isotropic springs' own ratio: no volume term, springs as they are.
  const physics::VolumeSpringParameters quarter =
    physics::volume_spring_parameters(0.25, 0.25);
  EXPECT_NEAR(quarter.spring_scale, 1.0, 1e-12);
  EXPECT_NEAR(quarter.volume_modulus, 0.0, 1e-12);
  // The volume term grows without bound towards incompressibility.
  EXPECT_GT(physics::volume_spring_parameters(0.49, 0.25).volume_modulus, 10);
  // On a lattice of ratio 0.117 the springs keep their shear modulus at that ratio.
  EXPECT_NEAR(physics::volume_spring_parameters(0.117, 0.117).spring_scale, 1.0, 1e-12);
  EXPECT_NEAR(physics::volume_spring_parameters(0.117, 0.117).volume_modulus, 0.0, 1e-12);
  // Everywhere: the springs (isotropic, of ratio ν_s) plus the term per tetrahedron
  // have the shear and bulk moduli of (E = 1, ν), and the term only adds stiffness.
  for (const double lattice : {0.05, 0.117, 0.25})
    for (const double nu : {0.0, 0.03, 0.1, 0.117, 0.2, 0.25, 0.3, 0.45, 0.49})
    {
      const physics::VolumeSpringParameters p =
        physics::volume_spring_parameters(nu, lattice);
      const double lattice_shear = 1 / (2 * (1 + lattice));
      const double lattice_bulk  = 1 / (3 * (1 - 2 * lattice));
      EXPECT_NEAR(p.spring_scale * lattice_shear + p.shear_modulus,
                  1 / (2 * (1 + nu)),
                  1e-12)
        << nu << ", " << lattice;
      EXPECT_NEAR(p.spring_scale * lattice_bulk + p.volume_modulus,
                  1 / (3 * (1 - 2 * nu)),
                  1e-12)
        << nu << ", " << lattice;
      EXPECT_GE(p.volume_modulus, 0) << nu << ", " << lattice;
      EXPECT_GE(p.shear_modulus, 0) << nu << ", " << lattice;
      EXPECT_EQ(p.volume_modulus * p.shear_modulus, 0) << nu << ", " << lattice;
      EXPECT_EQ(p.shear_modulus > 0, nu < lattice) << nu << ", " << lattice;
    }
}
