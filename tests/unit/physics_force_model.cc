// The force model's local update (ForceModel::springs_changed()): after springs are
// removed, moved, added and restiffened and particles appended, the model gives the
// forces and accelerations of a model made afresh for the same system.
#include <lacerta/physics/force_model.h>
#include <lacerta/physics/particle_ranges.h>
#include <lacerta/physics/particle_system.h>

#include <gtest/gtest.h>

#include "physics_test_support.h"
#include <algorithm>
#include <cmath>
#include <random>

using namespace lacerta;

namespace
{
  /// The largest difference between the forces (spring forces, then accelerations)
  /// of @p system's model and a model made afresh, relative to the largest force.
  std::array<double, 2>
  difference_to_a_fresh_model(const physics::ParticleSystem &system,
                              const unsigned int             n_threads,
                              std::mt19937                  &rng)
  {
    auto fresh = physics::ForceModelRegistry::create("linear springs");
    fresh->initialize(system, n_threads);
    std::uniform_real_distribution<double> jitter(-0.02, 0.02);
    std::vector<double>                    x(system.position), v(x.size());
    for (std::size_t i = 0; i < x.size(); ++i)
    {
      x[i] += jitter(rng);
      v[i] = 10 * jitter(rng);
    }
    std::array<double, 2> difference = {0, 0};
    for (unsigned int kind = 0; kind < 2; ++kind)
    {
      std::vector<double> mine(x.size()), theirs(x.size());
      if (kind == 0)
      {
        system.force_model().compute_spring_forces(system,
                                                   x.data(),
                                                   v.data(),
                                                   mine.data());
        fresh->compute_spring_forces(system, x.data(), v.data(), theirs.data());
      }
      else
      {
        system.force_model().compute_acceleration(system,
                                                  x.data(),
                                                  v.data(),
                                                  mine.data());
        fresh->compute_acceleration(system, x.data(), v.data(), theirs.data());
      }
      double largest = 0;
      for (std::size_t i = 0; i < x.size(); ++i)
      {
        largest          = std::max(largest, std::abs(theirs[i]));
        difference[kind] = std::max(difference[kind], std::abs(mine[i] - theirs[i]));
      }
      difference[kind] /= largest;
    }
    return difference;
  }
} // namespace


namespace
{
  /// Random local changes of the springs of a box's system on @p n_threads threads,
  /// 30 rounds; after each the model must be within @p tolerance of a fresh one.
  void
  expect_local_changes_match_a_fresh_model(const unsigned int n_threads,
                                           const double       tolerance)
  {
    const mesh::TetMesh mesh   = test_support::distorted_box(8, 0.2, {1, 1, 1});
    auto                system = test_support::make_system(mesh, 1000, 1e4, n_threads);
    system->spring_damping     = 1e-3;
    // A clamped slice, whose springs among themselves the model keeps apart: changes
    // move springs into and out of that set too.
    for (unsigned int i = 0; i < system->n_particles(); ++i)
      if (system->position[3 * i] < 0.2)
        system->free[i] = 0;
    system->update_force_model(n_threads);
    std::mt19937 rng(5);
    for (unsigned int round = 0; round < 30; ++round)
    {
      physics::SpringSet                    &springs = system->springs;
      std::vector<unsigned int>              changed;
      std::uniform_real_distribution<double> unit(0, 1);
      const auto                             any_spring = [&]
      { return static_cast<unsigned int>(unit(rng) * (springs.size() - 1)); };
      // New particles (as a cut's copies), joined to old ones far apart in the
      // numbering, so that their springs cross between ranges.
      for (unsigned int k = 0; k < 5; ++k)
      {
        const unsigned int old = static_cast<unsigned int>(unit(rng) * mesh.n_vertices());
        const unsigned int p =
          system->add_particle({{0, 0, 0}}, {{0, 0, 0}}, {{0, 0, 0}});
        for (unsigned int d = 0; d < 3; ++d)
          system->position[3 * p + d] = system->position[3 * old + d] + 0.01 * (d + 1);
        system->mass[p] = 0.5;
        for (const unsigned int other : {old, 0u, system->n_particles() / 2})
        {
          changed.push_back(springs.size());
          springs.push_back(p, other, 100 * (1 + unit(rng)), 0.02);
        }
      }
      // Retire springs as the mesh retires edges: the last one moves into the slot (new
      // springs too: listed, then gone, beyond the count the model knew).
      for (unsigned int k = 0; k < 20; ++k)
      {
        const unsigned int from = springs.size() - 1, to = k == 0 ? from : any_spring();
        springs.retire(to);
        changed.push_back(to);
      }
      // Restiffen some, and change some masses at their ends.
      for (unsigned int k = 0; k < 30; ++k)
      {
        const unsigned int s = any_spring();
        springs.stiffness[s] *= 0.5 + unit(rng);
        system->mass[springs.a[s]] *= 0.9 + 0.2 * unit(rng);
        changed.push_back(s);
      }
      system->springs_changed(changed);
      const auto difference = difference_to_a_fresh_model(*system, n_threads, rng);
      EXPECT_LE(difference[0], tolerance) << "spring forces, round " << round;
      EXPECT_LE(difference[1], tolerance) << "accelerations, round " << round;
    }
  }
} // namespace


TEST(ForceModelLocalUpdate, RandomLocalChangesGiveTheForcesOfAFreshModel)
{
  // On several ranges the springs' copies may sit in other ranges than a fresh
  // partition would put them: the same forces up to rounding.
  expect_local_changes_match_a_fresh_model(3, 1e-12);
}


TEST(ForceModelLocalUpdate, OnOneRangeTheForcesAreAFreshModelsToTheLastBit)
{
  // The springs are summed in the system's order, as initialize() sums them: a cut
  // leaves no trace of the update in the results.
  expect_local_changes_match_a_fresh_model(1, 0.0);
}


TEST(ForceModelLocalUpdate, RemovingEverySpringLeavesNoForce)
{
  const mesh::TetMesh mesh   = test_support::distorted_box(4, 0.2, {1, 1, 1});
  auto                system = test_support::make_system(mesh, 1000, 1e4, 2);
  const std::size_t   n      = system->springs.size();
  system->springs.clear();
  system->springs_changed({});
  std::vector<double> f(system->position.size(), 1.0);
  system->force_model().compute_spring_forces(*system,
                                              system->position.data(),
                                              system->velocity.data(),
                                              f.data());
  EXPECT_EQ(*std::max_element(f.begin(), f.end()), 0.0) << n << " springs removed";
  EXPECT_EQ(*std::min_element(f.begin(), f.end()), 0.0) << n << " springs removed";
}


namespace
{
  /// Spring forces of @p springs (with damping @p beta) at (@p x, @p v), summed in the
  /// springs' order: the spring law as the paper writes it, with no partition.
  std::vector<double>
  forces_of_springs(const physics::SpringSet  &springs,
                    const double               beta,
                    const std::vector<double> &x,
                    const std::vector<double> &v)
  {
    std::vector<double> f(x.size(), 0.0);
    for (std::size_t s = 0; s < springs.size(); ++s)
    {
      const std::size_t i = 3 * std::size_t(springs.a[s]),
                        j = 3 * std::size_t(springs.b[s]);
      const double dx = x[j] - x[i], dy = x[j + 1] - x[i + 1], dz = x[j + 2] - x[i + 2];
      const double len       = std::sqrt(dx * dx + dy * dy + dz * dz);
      const double inv       = 1.0 / len;
      const double k         = springs.stiffness[s];
      double       magnitude = k * (len - springs.rest_length[s]);
      if (beta > 0)
        magnitude += beta * k * inv
                     * ((v[j] - v[i]) * dx + (v[j + 1] - v[i + 1]) * dy
                        + (v[j + 2] - v[i + 2]) * dz);
      const double scale = magnitude * inv;
      for (unsigned int d = 0; d < 3; ++d)
      {
        const double component = scale * (d == 0 ? dx : d == 1 ? dy : dz);
        f[i + d] += component;
        f[j + d] -= component;
      }
    }
    return f;
  }
} // namespace


TEST(LinearSprings, LargeRangesGiveTheSpringLawToTheLastBit)
{
  // 34³ = 39,304 particles: on one thread the range is large enough for the loop to
  // fetch ahead (doc/physics.md, "The hot loop"), which must not change a bit of the
  // forces: a plain loop over the springs in their order, with and without damping.
  const mesh::TetMesh mesh   = test_support::distorted_box(33, 0.2, {1, 1, 1});
  auto                system = test_support::make_system(mesh, 1000, 1e4, 1);
  ASSERT_GT(system->n_particles(), 32768u);
  std::mt19937                           rng(7);
  std::uniform_real_distribution<double> jitter(-0.005, 0.005);
  std::vector<double>                    x(system->position), v(x.size());
  for (std::size_t i = 0; i < x.size(); ++i)
  {
    x[i] += jitter(rng);
    v[i] = 10 * jitter(rng);
  }
  for (const double beta : {0.0, 1e-3})
  {
    system->spring_damping = beta;
    std::vector<double> mine(x.size());
    system->force_model().compute_spring_forces(*system, x.data(), v.data(), mine.data());
    const std::vector<double> expected =
      forces_of_springs(system->springs, system->spring_damping, x, v);
    EXPECT_EQ(mine, expected) << "damping " << beta;
  }
}


TEST(LinearSprings, SpringsBetweenPrescribedParticlesActOnNoFreeParticle)
{
  // A box clamped over a third of its length, its springs stretched and moving: the
  // model leaves out the springs between two clamped particles, so the free
  // particles' accelerations are those of every spring, to the last bit on one range
  // (the skipped springs add nothing to a free particle's sum), and the clamped ones'
  // are zero. The spring forces and the elastic energy are those of the other springs:
  // on a clamped particle, the reaction of the free material.
  const mesh::TetMesh mesh = test_support::distorted_box(6, 0.2, {1, 1, 1});
  for (const unsigned int n_threads : {1u, 3u})
  {
    auto system            = test_support::make_system(mesh, 1000, 1e4, n_threads);
    system->spring_damping = 1e-3;
    unsigned int clamped   = 0;
    for (unsigned int i = 0; i < system->n_particles(); ++i)
      if (system->position[3 * i] < 0.34)
      {
        system->free[i] = 0;
        ++clamped;
      }
    system->update_force_model(n_threads);
    ASSERT_GT(clamped, system->n_particles() / 4);

    std::mt19937                           rng(11);
    std::uniform_real_distribution<double> jitter(-0.02, 0.02);
    std::vector<double>                    x(system->position), v(x.size());
    for (std::size_t i = 0; i < x.size(); ++i)
    {
      x[i] += jitter(rng);
      v[i] = 10 * jitter(rng);
    }
    // The springs with a free end, and the forces of every spring and of those.
    physics::SpringSet        acting;
    const physics::SpringSet &springs = system->springs;
    for (std::size_t s = 0; s < springs.size(); ++s)
      if (system->free[springs.a[s]] > 0 || system->free[springs.b[s]] > 0)
        acting.push_back(springs.a[s],
                         springs.b[s],
                         springs.stiffness[s],
                         springs.rest_length[s]);
    ASSERT_LT(acting.size(), springs.size());
    const std::vector<double> expected =
      forces_of_springs(springs, system->spring_damping, x, v);
    const std::vector<double> reactions =
      forces_of_springs(acting, system->spring_damping, x, v);

    std::vector<double> a(x.size());
    system->compute_acceleration(x.data(), v.data(), a.data());
    double largest = 0, worst = 0;
    for (unsigned int i = 0; i < system->n_particles(); ++i)
      for (unsigned int d = 0; d < 3; ++d)
      {
        const std::size_t k = 3 * std::size_t(i) + d;
        if (system->free[i] == 0)
        {
          EXPECT_EQ(a[k], 0.0) << "clamped particle " << i;
          continue;
        }
        const double wanted = expected[k] * (1.0 / system->mass[i]);
        largest             = std::max(largest, std::abs(wanted));
        worst               = std::max(worst, std::abs(a[k] - wanted));
        if (n_threads == 1)
          EXPECT_EQ(a[k], wanted) << "free particle " << i;
      }
    EXPECT_LE(worst, 1e-12 * largest) << n_threads << " threads";

    std::vector<double> f(x.size());
    system->force_model().compute_spring_forces(*system, x.data(), v.data(), f.data());
    double largest_force = 0, worst_force = 0;
    for (std::size_t k = 0; k < f.size(); ++k)
    {
      largest_force = std::max(largest_force, std::abs(reactions[k]));
      worst_force   = std::max(worst_force, std::abs(f[k] - reactions[k]));
    }
    EXPECT_LE(worst_force, 1e-12 * largest_force) << n_threads << " threads";

    double energy = 0;
    for (std::size_t s = 0; s < acting.size(); ++s)
    {
      const std::size_t i = 3 * std::size_t(acting.a[s]),
                        j = 3 * std::size_t(acting.b[s]);
      const double length =
        std::hypot(x[j] - x[i], x[j + 1] - x[i + 1], x[j + 2] - x[i + 2]);
      energy += 0.5 * acting.stiffness[s] * std::pow(length - acting.rest_length[s], 2);
    }
    EXPECT_NEAR(system->force_model().elastic_energy(*system, x.data()),
                energy,
                1e-12 * energy)
      << n_threads << " threads";
  }
}


TEST(ParticleRanges, RangesAreSplitAgainWhenOneExceedsTheMeanByATenth)
{
  using physics::ParticleRanges;
  EXPECT_FALSE(ParticleRanges::unbalanced({50000})) << "one range";
  EXPECT_FALSE(ParticleRanges::unbalanced({10000, 10000})) << "equal loads";
  // Mean 11,500: the limit is 1.1 · 11,500 + 256 = 12,906.
  EXPECT_TRUE(ParticleRanges::unbalanced({10000, 13000}));
  EXPECT_FALSE(ParticleRanges::unbalanced({10000, 12000}));
  EXPECT_TRUE(ParticleRanges::unbalanced({10000, 10000, 14000}));
  // A small system is not split again for a few springs.
  EXPECT_FALSE(ParticleRanges::unbalanced({0, 300}));
}
