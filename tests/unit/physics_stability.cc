// Integrators and stability control: energy behaviour, the critical time step bound
// against the true limit from an eigen-solver, and blow-up detection.

#include <lacerta/base/exceptions.h>
#include <lacerta/physics/force_model.h>
#include <lacerta/physics/integrator.h>
#include <lacerta/physics/particle_ranges.h>
#include <lacerta/physics/stability.h>

#include <gtest/gtest.h>

#include "physics_test_support.h"
#include <cstdio>
#include <limits>
#include <memory>
#include <random>

using namespace lacerta;
using test_support::true_highest_frequency;

namespace
{
  void
  perturb(std::vector<double> &values, const double amplitude, const unsigned int seed)
  {
    std::mt19937                           random(seed);
    std::uniform_real_distribution<double> uniform(-amplitude, amplitude);
    for (double &v : values)
      v += uniform(random);
  }


  double
  mechanical_energy(const physics::ParticleSystem &system)
  {
    return system.kinetic_energy() + system.elastic_energy();
  }
} // namespace


TEST(Stability, BoundIsAboveTheTrueFrequencyAndWithinFactorTwo)
{
  struct Case
  {
    unsigned int n;
    double       distortion;
    double       stretch; // random position perturbation relative to the cell size
    bool         clamp;
  };
  for (const Case c : {Case{1, 0.0, 0.0, false},
                       Case{2, 0.0, 0.0, true},
                       Case{2, 0.3, 0.0, false},
                       Case{3, 0.3, 0.0, true},
                       Case{3, 0.2, 0.15, false},
                       Case{3, 0.0, 0.3, true}})
  {
    const mesh::TetMesh mesh =
      test_support::distorted_box(c.n, c.distortion, dealii::Point<3>(0.1, 0.05, 0.02));
    auto system = test_support::make_system(mesh, 1000, 1e5);
    if (c.clamp)
      for (unsigned int i = 0; i < system->n_particles(); ++i)
        if (system->position[3 * i] < 1e-12)
          system->free[i] = 0;
    perturb(system->position, c.stretch * 0.02 / c.n, c.n);
    const double true_omega = true_highest_frequency(*system);
    const double bound      = physics::bound_highest_frequency(*system).omega;
    EXPECT_GE(bound, true_omega * (1 - 1e-12)) << "n = " << c.n;
    EXPECT_LE(bound, 2.0 * true_omega) << "n = " << c.n;
    // So every integrator's time step from the bound is safe and at least half the true
    // one.
    for (const auto &[name, entry] : physics::IntegratorRegistry::plugins())
    {
      if (name == "explicit_euler")
        continue;
      const auto   integrator = physics::IntegratorRegistry::create(name);
      const double from_bound = integrator->critical_time_step(bound, 0, 0);
      const double true_limit = integrator->critical_time_step(true_omega, 0, 0);
      EXPECT_LE(from_bound, true_limit * (1 + 1e-12)) << name;
      EXPECT_GE(from_bound, 0.5 * true_limit) << name;
    }
  }
}


TEST(Stability, WeightedRowsBoundTheFrequencyForEveryPositiveWeightAndLowerGershgorin)
{
  // The weighted rows bound the true frequency for any positive weights (the local
  // update relies on it, whatever weights it keeps), and the weights of
  // gershgorin_row_weight() give a lower bound than block Gershgorin with all weights
  // 1, and those of refined_row_weight() (one power step on) a lower one still.
  // Random masses (a factor 100 apart, as next to a cut) and random weights spanning
  // 10^6.
  std::mt19937                           random(3);
  std::uniform_real_distribution<double> log_weight(-3, 3), log_mass(-1, 1);
  unsigned int                           n_lowered = 0, n_refined = 0, n_cases = 0;
  for (const unsigned int n : {2u, 3u})
    for (const bool clamp : {false, true})
    {
      const mesh::TetMesh mesh =
        test_support::distorted_box(n, 0.3, dealii::Point<3>(0.1, 0.05, 0.02));
      auto system = test_support::make_system(mesh, 1000, 1e5);
      for (double &m : system->mass)
        m *= std::pow(10.0, log_mass(random));
      if (clamp)
        for (unsigned int i = 0; i < system->n_particles(); ++i)
          if (system->position[3 * i] < 1e-12)
            system->free[i] = 0;
      perturb(system->position, 0.2 * 0.02 / n, n);
      const double                   true_omega = true_highest_frequency(*system);
      const physics::GershgorinTerms terms =
        physics::gershgorin_terms(*system, system->position.data());
      const auto largest = [](const std::vector<double> &lambda)
      { return std::sqrt(*std::max_element(lambda.begin(), lambda.end())); };
      const auto highest = [&](const std::vector<double> &weights)
      { return largest(physics::weighted_frequency_bounds(*system, terms, weights)); };
      for (unsigned int trial = 0; trial < 20; ++trial)
      {
        std::vector<double> weights(system->n_particles());
        for (double &w : weights)
          w = std::pow(10.0, log_weight(random));
        EXPECT_GE(highest(weights), true_omega * (1 - 1e-12)) << "n = " << n;
      }
      const double plain = largest(physics::squared_frequency_bounds(*system, terms));
      const std::vector<double> first  = physics::gershgorin_row_weights(*system, terms);
      const double              scaled = highest(first);
      EXPECT_GE(scaled, true_omega * (1 - 1e-12)) << "n = " << n;
      EXPECT_LE(scaled, plain * (1 + 1e-12)) << "n = " << n;
      const double refined = highest(physics::refined_row_weights(*system, terms, first));
      EXPECT_GE(refined, true_omega * (1 - 1e-12)) << "n = " << n;
      EXPECT_LE(refined, scaled * (1 + 1e-12)) << "n = " << n;
      EXPECT_DOUBLE_EQ(physics::bound_highest_frequency(*system).omega, refined);
      n_lowered += scaled < 0.95 * plain;
      n_refined += refined - true_omega < 0.75 * (scaled - true_omega);
      ++n_cases;
      std::printf("n = %u, clamped %d: true %.1f, block Gershgorin %.1f, first weights "
                  "%.1f, refined %.1f rad/s\n",
                  n,
                  int(clamp),
                  true_omega,
                  plain,
                  scaled,
                  refined);
    }
  // The scaling is not a no-op: it lowers the bound by 5 % or more on most cases, and
  // the power step closes a quarter or more of what remains above the true frequency
  // on most.
  EXPECT_GE(n_lowered, 3u) << "of " << n_cases;
  EXPECT_GE(n_refined, 3u) << "of " << n_cases;
}


TEST(Stability, SymplecticIntegratorsKeepEnergyBoundedOver10000Steps)
{
  const mesh::TetMesh mesh =
    test_support::distorted_box(2, 0.2, dealii::Point<3>(0.1, 0.1, 0.1));
  for (const std::string name : {"symplectic_euler", "velocity_verlet"})
  {
    auto system = test_support::make_system(mesh, 1000, 1e5);
    perturb(system->position, 0.002, 7);
    const auto integrator = physics::IntegratorRegistry::create(name);
    integrator->initialize(*system);
    const double dt =
      0.5 * integrator->critical_time_step(true_highest_frequency(*system), 0, 0);
    const double initial           = mechanical_energy(*system);
    double       largest_deviation = 0, first_window = 0, last_window = 0;
    for (unsigned int step = 0; step < 10000; ++step)
    {
      integrator->step(*system, step * dt, dt);
      const double energy = mechanical_energy(*system);
      largest_deviation   = std::max(largest_deviation, std::abs(energy - initial));
      (step < 1000 ? first_window : last_window) +=
        (step < 1000 || step >= 9000) ? energy / 1000 : 0;
    }
    // A symplectic scheme conserves a modified energy: the true one oscillates by
    // O(ω dt) (symplectic Euler, velocities half a step off) or O((ω dt)²) (Verlet)
    // around it, at ω dt = 1 here, but it never drifts.
    EXPECT_LT(largest_deviation, (name == "velocity_verlet" ? 0.25 : 0.75) * initial)
      << name;
    EXPECT_NEAR(last_window, first_window, 0.02 * first_window) << name;
  }
}


TEST(Stability, Rk4LosesEnergySlowlyAndExplicitEulerGainsIt)
{
  const mesh::TetMesh mesh =
    test_support::distorted_box(2, 0.2, dealii::Point<3>(0.1, 0.1, 0.1));
  for (const std::string name : {"rk4", "explicit_euler"})
  {
    auto system = test_support::make_system(mesh, 1000, 1e5);
    perturb(system->position, 0.002, 7);
    const auto integrator = physics::IntegratorRegistry::create(name);
    integrator->initialize(*system);
    const double dt      = 0.1 / true_highest_frequency(*system);
    const double initial = mechanical_energy(*system);
    for (unsigned int step = 0; step < 2000; ++step)
      integrator->step(*system, step * dt, dt);
    if (name == "rk4")
    {
      EXPECT_LE(mechanical_energy(*system), initial * (1 + 1e-9));
      EXPECT_GT(mechanical_energy(*system), 0.5 * initial);
    }
    else
      EXPECT_GT(mechanical_energy(*system), 1.1 * initial);
  }
}


TEST(Stability, AStepSlightlyAboveTheTrueLimitIsCaught)
{
  const mesh::TetMesh mesh =
    test_support::distorted_box(2, 0.2, dealii::Point<3>(0.1, 0.1, 0.1));
  for (const std::string name : {"symplectic_euler", "velocity_verlet", "rk4"})
  {
    auto system = test_support::make_system(mesh, 1000, 1e5);
    perturb(system->position, 1e-4, 3);
    const auto integrator = physics::IntegratorRegistry::create(name);
    integrator->initialize(*system);
    // The linear limit (the symplectic schemes are kept below their nonlinear
    // resonance, under it).
    const double true_omega = true_highest_frequency(*system);
    const double true_limit =
      name == "rk4" ? integrator->critical_time_step(true_omega, 0, 0)
                    : physics::symplectic_linear_stability_limit(true_omega, 0);
    const double dt = 1.02 * true_limit;
    // Before the run: the limit from the bound is below the step, so the simulator
    // sub-steps or stops.
    const double bound = physics::bound_highest_frequency(*system).omega;
    EXPECT_LT(integrator->critical_time_step(bound, 0, 0), dt) << name;
    // During the run: the blow-up monitor stops it with a message.
    physics::BlowUpMonitor monitor(*system, 1.0);
    bool                   caught = false;
    try
    {
      for (unsigned int step = 1; step <= 20000; ++step)
      {
        integrator->step(*system, step * dt, dt);
        if (step % 10 == 0)
          monitor.check(*system, step, step * dt);
      }
    }
    catch (const Error &e)
    {
      caught = std::string(e.what()).find("blew up at step") != std::string::npos;
    }
    EXPECT_TRUE(caught) << name;
  }
}


TEST(Stability, MonitorAcceptsAStableDampedRunWithWorkInput)
{
  // A clamped box pulled by a moving face under gravity: energy enters through the
  // prescribed motion and leaves through damping; no false alarm.
  const mesh::TetMesh mesh =
    test_support::distorted_box(3, 0.0, dealii::Point<3>(0.1, 0.03, 0.03));
  auto system               = test_support::make_system(mesh, 1000, 1e5);
  system->mass_damping      = 2;
  system->body_acceleration = {0, 0, -9.81};
  std::vector<unsigned int> pulled;
  for (unsigned int i = 0; i < system->n_particles(); ++i)
    if (system->position[3 * i] < 1e-12 || system->position[3 * i] > 0.1 - 1e-12)
    {
      system->free[i] = 0;
      if (system->position[3 * i] > 0.05)
        pulled.push_back(i);
    }
  double prescribed_time      = 0;
  system->prepare_constraints = [&](const double t) { prescribed_time = t; };
  system->prescribe_constraints =
    [&](double *x, double *v, const unsigned int begin, const unsigned int end)
  {
    for (const unsigned int i : pulled)
      if (i >= begin && i < end)
      {
        x[3 * i] = system->rest_position()[3 * i] + 0.01 * prescribed_time;
        v[3 * i] = 0.01;
      }
  };
  const auto integrator = physics::IntegratorRegistry::create("velocity_verlet");
  integrator->initialize(*system);
  const double dt =
    0.5
    * integrator->critical_time_step(physics::bound_highest_frequency(*system).omega,
                                     2,
                                     0);
  physics::BlowUpMonitor monitor(*system, 1.0);
  for (unsigned int step = 1; step <= 5000; ++step)
  {
    integrator->step(*system, step * dt, dt);
    if (step % 10 == 0)
    {
      EXPECT_NO_THROW(monitor.check(*system, step, step * dt));
    }
  }
  EXPECT_GT(monitor.input_work(), 0.0);
}


namespace
{
  /// The box of the monitor tests below.
  mesh::TetMesh
  swinging_box_mesh()
  {
    return test_support::distorted_box(2, 0.0, dealii::Point<3>(0.1, 0.03, 0.03));
  }

  /// A particle system on @p mesh swinging about the y axis with some kinetic energy.
  std::unique_ptr<physics::ParticleSystem>
  swinging_box(const mesh::TetMesh &mesh)
  {
    auto system = test_support::make_system(mesh, 1000, 1e5);
    for (unsigned int i = 0; i < system->n_particles(); ++i)
      system->velocity[3 * i + 1] = 0.01 * system->position[3 * i];
    return system;
  }
} // namespace


TEST(Stability, MonitorCatchesFiniteEnergyGrowthWithTheDefaultTolerance)
{
  // A box swinging with some kinetic energy; its velocities then grow tenfold (energy
  // x100, still finite). The energy scale once included the state under test, so that
  // with the default tolerance 1 this passed (a kidney_cut variant reached 1e127 J).
  const mesh::TetMesh    mesh   = swinging_box_mesh();
  auto                   system = swinging_box(mesh);
  physics::BlowUpMonitor monitor(*system, 1.0);
  EXPECT_NO_THROW(monitor.check(*system, 1, 1e-3));
  for (double &v : system->velocity)
    v *= 10;
  try
  {
    monitor.check(*system, 2, 2e-3);
    ADD_FAILURE() << "a hundredfold energy growth was not caught";
  }
  catch (const Error &e)
  {
    const std::string message = e.what();
    EXPECT_NE(message.find("blew up at step 2, time 0.002 s"), std::string::npos)
      << message;
    EXPECT_NE(message.find("mechanical energy"), std::string::npos) << message;
  }
}


TEST(Stability, MonitorChecksAndRestartsItsLedgerAtASystemChange)
{
  // A change that removes energy passes and the ledger restarts from it; one that
  // adds energy (as a state transfer putting particles far off would) stops the run
  // naming the change.
  const mesh::TetMesh    mesh   = swinging_box_mesh();
  auto                   system = swinging_box(mesh);
  physics::BlowUpMonitor monitor(*system, 1.0);
  for (double &v : system->velocity)
    v *= 0.5;
  EXPECT_NO_THROW(monitor.restart(*system, 1, 1e-3, "the cut"));
  // Four times the initial energy, sixteen times the ledger after the loss: caught.
  for (double &v : system->velocity)
    v *= 4;
  try
  {
    monitor.restart(*system, 2, 2e-3, "the re-extraction of the level of detail");
    ADD_FAILURE() << "the energy added by the change was not caught";
  }
  catch (const Error &e)
  {
    const std::string message = e.what();
    EXPECT_NE(message.find("right after the re-extraction of the level of detail"),
              std::string::npos)
      << message;
  }
  // Non-finite values after a change are named too.
  system->position[4] = std::numeric_limits<double>::quiet_NaN();
  try
  {
    monitor.restart(*system, 3, 3e-3, "the MT update after the stroke");
    ADD_FAILURE() << "a NaN position was not caught";
  }
  catch (const Error &e)
  {
    const std::string message = e.what();
    EXPECT_NE(message.find("not a finite number"), std::string::npos) << message;
    EXPECT_NE(message.find("right after the MT update"), std::string::npos) << message;
  }
}


TEST(Stability, ParallelForcesEqualSerialForces)
{
  const mesh::TetMesh mesh =
    test_support::distorted_box(6, 0.2, dealii::Point<3>(0.1, 0.1, 0.1));
  auto serial = test_support::make_system(mesh, 1000, 1e5, 1);
  auto dual   = test_support::make_system(mesh, 1000, 1e5, 2);
  perturb(serial->position, 0.002, 5);
  perturb(serial->velocity, 0.1, 6);
  serial->spring_damping = dual->spring_damping = 1e-3;
  dual->position                                = serial->position;
  dual->velocity                                = serial->velocity;
  std::vector<double> a1(serial->position.size()), a2(serial->position.size());
  serial->compute_acceleration(serial->position.data(),
                               serial->velocity.data(),
                               a1.data());
  dual->compute_acceleration(dual->position.data(), dual->velocity.data(), a2.data());
  double scale = 0;
  for (const double a : a1)
    scale = std::max(scale, std::abs(a));
  for (std::size_t i = 0; i < a1.size(); ++i)
    EXPECT_NEAR(a1[i], a2[i], 1e-12 * scale);
}


TEST(Stability, MultirateShareCountsEachSpringAtItsOwnStep)
{
  // Three separate springs of one stiffness whose particles weigh 1, 4 and 16 times as
  // much: their frequencies are ω, ω/2 and ω/4, so multi-rate stepping evaluates them
  // every step, every second and every fourth step.
  std::vector<double> rest;
  for (unsigned int i = 0; i < 6; ++i)
    for (const double x : {0.1 * i, 0.0, 0.0})
      rest.push_back(x);
  physics::ParticleSystem system(rest);
  system.mass = {1, 1, 4, 4, 16, 16};
  for (unsigned int s = 0; s < 3; ++s)
    system.springs.push_back(2 * s, 2 * s + 1, 100, 0.1);
  system.set_force_model(physics::ForceModelRegistry::create("linear springs"), 1);

  const std::vector<double> omega = physics::particle_frequency_bounds(system);
  EXPECT_NEAR(omega[2], omega[0] / 2, 1e-12 * omega[0]);
  EXPECT_NEAR(omega[4], omega[0] / 4, 1e-12 * omega[0]);
  EXPECT_DOUBLE_EQ(physics::bound_highest_frequency(system).omega, omega[0]);
  EXPECT_NEAR(physics::multirate_evaluation_share(system), (1 + 0.5 + 0.25) / 3, 1e-12);

  // Equal particles: nothing to save.
  system.mass = {1, 1, 1, 1, 1, 1};
  EXPECT_DOUBLE_EQ(physics::multirate_evaluation_share(system), 1.0);
}


TEST(Stability, BoundsOnSeveralThreadsEqualThoseOnOneToTheBit)
{
  // The bound's passes over the whole system run in the force model's thread ranges,
  // each adding its rows' terms in spring order: the same sums as on one thread.
  // (Corotated FEM visits its tetrahedra range by range, so its element terms are
  // summed in another order on another number of threads.)
  const mesh::TetMesh mesh =
    test_support::distorted_box(6, 0.2, dealii::Point<3>(0.1, 0.1, 0.1));
  for (const std::string model : {"linear springs", "volume springs"})
  {
    SCOPED_TRACE(model);
    auto serial = test_support::make_system(mesh, 1000, 1e5, 1, model);
    auto dual   = test_support::make_system(mesh, 1000, 1e5, 2, model);
    ASSERT_GT(dual->force_model().particle_ranges().n_parts(), 1u);
    perturb(serial->position, 0.002, 5);
    perturb(serial->mass, 1e-4, 7);
    for (unsigned int i = 0; i < serial->n_particles(); i += 17)
      serial->free[i] = 0;
    dual->position = serial->position;
    dual->mass     = serial->mass;
    dual->free     = serial->free;
    std::vector<double>                    weights(serial->n_particles());
    std::mt19937                           random(8);
    std::uniform_real_distribution<double> log_weight(-2, 2);
    for (double &w : weights)
      w = std::exp(log_weight(random));

    {
      const physics::GershgorinTerms one =
        physics::gershgorin_terms(*serial, serial->position.data());
      const physics::GershgorinTerms two =
        physics::gershgorin_terms(*dual, dual->position.data());
      EXPECT_EQ(one.diagonal, two.diagonal);
      EXPECT_EQ(one.coupling, two.coupling);
      EXPECT_EQ(one.stiffest_spring, two.stiffest_spring);
      EXPECT_EQ(one.spring_block, two.spring_block);
      EXPECT_EQ(one.element_block, two.element_block);
      EXPECT_EQ(one.element_coupling, two.element_coupling);
      EXPECT_EQ(physics::weighted_frequency_bounds(*serial, one, weights),
                physics::weighted_frequency_bounds(*dual, two, weights));
      EXPECT_EQ(physics::squared_frequency_bounds(*serial, one),
                physics::squared_frequency_bounds(*dual, two));
    }
    // The rows of the periodic check, made without keeping the springs' terms.
    const physics::GershgorinTerms terms =
      physics::gershgorin_terms(*serial, serial->position.data());
    const std::vector<double> rows =
      physics::weighted_frequency_bounds(*serial, terms, weights);
    for (const auto *system : {serial.get(), dual.get()})
    {
      std::vector<unsigned int> stiffest;
      EXPECT_EQ(physics::weighted_frequency_bounds_at(
                  *system, system->position.data(), weights, stiffest),
                rows);
      EXPECT_EQ(stiffest, terms.stiffest_spring);
    }
    const physics::FrequencyBound one = physics::bound_highest_frequency(*serial);
    const physics::FrequencyBound two = physics::bound_highest_frequency(*dual);
    EXPECT_EQ(one.omega, two.omega);
    EXPECT_EQ(one.particle, two.particle);
    EXPECT_EQ(one.spring, two.spring);
  }
}


TEST(Stability, IntegratorsOnSeveralThreadsFollowTheSerialRun)
{
  // The updates of positions and velocities run in the force model's thread ranges:
  // every coordinate is updated once, whatever the ranges (the forces differ from the
  // serial ones only by the order of their sums).
  const mesh::TetMesh mesh =
    test_support::distorted_box(6, 0.2, dealii::Point<3>(0.1, 0.1, 0.1));
  for (const auto &[name, entry] : physics::IntegratorRegistry::plugins())
  {
    SCOPED_TRACE(name);
    auto serial = test_support::make_system(mesh, 1000, 1e5, 1);
    auto dual   = test_support::make_system(mesh, 1000, 1e5, 2);
    ASSERT_GT(dual->force_model().particle_ranges().n_parts(), 1u);
    perturb(serial->position, 0.002, 9);
    dual->position = serial->position;
    const auto one = physics::IntegratorRegistry::create(name);
    const auto two = physics::IntegratorRegistry::create(name);
    one->initialize(*serial);
    two->initialize(*dual);
    // A tenth of the symplectic limit (explicit Euler has none without damping).
    const double dt = 0.1 * 2 / true_highest_frequency(*serial);
    for (unsigned int step = 0; step < 20; ++step)
    {
      one->step(*serial, step * dt, dt);
      two->step(*dual, step * dt, dt);
    }
    double moved = 0;
    for (std::size_t c = 0; c < serial->velocity.size(); ++c)
      moved = std::max(moved, std::abs(serial->velocity[c]));
    ASSERT_GT(moved, 0);
    for (std::size_t c = 0; c < serial->position.size(); ++c)
    {
      EXPECT_NEAR(dual->position[c], serial->position[c], 1e-9 * moved * 20 * dt);
      EXPECT_NEAR(dual->velocity[c], serial->velocity[c], 1e-9 * moved);
    }
  }
}
