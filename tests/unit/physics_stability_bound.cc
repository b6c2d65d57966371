// The stability bound kept per particle (physics/stability_bound.h): after cuts, its
// local updates give what the bound over the whole system gives, for every force
// model; and the blow-up monitor follows local changes without a global restart.
#include <lacerta/cut/tool.h>
#include <lacerta/physics/particle_system.h>
#include <lacerta/physics/stability.h>
#include <lacerta/physics/stability_bound.h>
#include <lacerta/scene/scene.h>

#include <gtest/gtest.h>

#include "mt_test_support.h"
#include "physics_test_support.h"
#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <random>
#include <sstream>

namespace lacerta
{
  using test_support::slab_cut_scene;


  TEST(StabilityBound, LocalUpdatesAfterCutsEqualTheBoundOfTheWholeSystem)
  {
    // Random straight strokes across the slab, on a tissue moved off its rest shape
    // (the geometric stiffness counts): after every blade motion the bound updated
    // around the changed particles equals, at every particle, the one computed over
    // the whole system with the same row weights; the weights it chose keep it below
    // the bound with all weights 1, and above the true frequency.
    std::mt19937                           random(7);
    std::uniform_real_distribution<double> across(-0.045, 0.045);
    unsigned int                           n_compared = 0;
    for (const std::string model : {"linear springs", "volume springs", "corotated fem"})
      for (unsigned int stroke = 0; stroke < 3; ++stroke)
      {
        const double             x0 = across(random), x1 = across(random);
        auto                     scene  = slab_cut_scene(model, x0, 0.07, x1, -0.07);
        physics::ParticleSystem &system = *scene->system;
        std::uniform_real_distribution<double> jitter(-5e-4, 5e-4);
        for (double &x : system.position)
          x += jitter(random);
        physics::StabilityBound bound;
        bound.compute(system);
        system.clear_changes();
        const unsigned int before = system.n_particles();
        for (unsigned int k = 1; k <= 16; ++k)
        {
          scene->cut(scene->tool->blade(k / 16.0), 0.01 * k);
          // The springs are the mesh's edges, so the update is local (not the full
          // computation it falls back to otherwise).
          ASSERT_EQ(scene->mesh.n_edges(), system.springs.size());
          ASSERT_FALSE(system.all_particles_changed());
          bound.update(system, system.changed_particles());
          system.clear_changes();
          const physics::GershgorinTerms terms =
            physics::gershgorin_terms(system, system.position.data());
          ASSERT_EQ(bound.row_weights().size(), system.n_particles());
          for (const double w : bound.row_weights())
            ASSERT_TRUE(w > 0 && std::isfinite(w)) << model << ", motion " << k;
          const std::vector<double> whole =
            physics::weighted_frequency_bounds(system, terms, bound.row_weights());
          const std::vector<double> plain =
            physics::squared_frequency_bounds(system, terms);
          double highest = 0, highest_plain = 0;
          for (unsigned int i = 0; i < system.n_particles(); ++i)
          {
            highest       = std::max(highest, whole[i]);
            highest_plain = std::max(highest_plain, plain[i]);
            EXPECT_NEAR(bound.squared_frequency(i), whole[i], 1e-11 * whole[i])
              << model << ", stroke " << stroke << ", motion " << k << ", particle " << i;
          }
          EXPECT_NEAR(bound.bound().omega,
                      std::sqrt(highest),
                      1e-11 * std::sqrt(highest));
          EXPECT_LE(bound.bound().omega, std::sqrt(highest_plain))
            << model << ", stroke " << stroke << ", motion " << k;
          ++n_compared;
        }
        EXPECT_GT(system.n_particles(), before) << model << ": the strokes cut nothing";
        // The true frequency of the springs (the first model has nothing else).
        if (model == "linear springs")
        {
          EXPECT_GE(bound.bound().omega,
                    test_support::true_highest_frequency(system) * (1 - 1e-12));
        }
      }
    EXPECT_EQ(n_compared, 3u * 3u * 16u);
  }


  TEST(StabilityBound, ThePeriodicCheckAgreesWithTheHighestRowWithKeptWeights)
  {
    // kept_weights_within() settles most rows without bounding them; in any sequence
    // of positions, for every force model and every limit, it must say what the
    // highest row of bound_with_kept_weights() says. Positions: a cut slab moving
    // away from its rest shape step by step (so that the check's reference ages),
    // with or without springs collapsed below half their rest length; limits around
    // the highest row.
    std::mt19937 random(11);
    unsigned int n_compared = 0, n_within = 0;
    for (const std::string model : {"linear springs", "volume springs", "corotated fem"})
    {
      auto                     scene  = slab_cut_scene(model, 0.01, 0.07, -0.02, -0.07);
      physics::ParticleSystem &system = *scene->system;
      for (unsigned int k = 1; k <= 8; ++k)
        scene->cut(scene->tool->blade(k / 16.0), 0.01 * k);
      system.clear_changes();
      physics::StabilityBound bound;
      bound.compute(system);
      std::vector<double>                    drift(system.position.size());
      std::uniform_real_distribution<double> unit(-1, 1);
      for (double &d : drift)
        d = unit(random);
      // A motion that raises the highest row past the limit after the check took its
      // reference is caught.
      {
        const auto squared_highest = [&]()
        {
          const double omega = bound.bound_with_kept_weights(system)->omega;
          return omega * omega;
        };
        const std::vector<double> start = system.position;
        const double              h0    = squared_highest();
        EXPECT_TRUE(bound.kept_weights_within(system, 100 * h0));
        double h1 = h0;
        for (double scale = 1e-5; h1 < 1.02 * h0 && scale < 0.1; scale *= 1.2)
        {
          for (std::size_t c = 0; c < drift.size(); ++c)
            system.position[c] = start[c] + scale * drift[c];
          h1 = squared_highest();
        }
        ASSERT_GT(h1, 1.02 * h0) << model;
        EXPECT_FALSE(bound.kept_weights_within(system, std::sqrt(h0 * h1))) << model;
        EXPECT_TRUE(bound.kept_weights_within(system, 1.001 * h1)) << model;
        system.position = start;
      }
      for (const double amplitude : {0.0, 1e-5, 1e-4, 3e-4, 2e-3})
        for (const bool collapse : {false, true})
        {
          const std::vector<double> before = system.position;
          for (std::size_t c = 0; c < drift.size(); ++c)
            system.position[c] += amplitude * (drift[c] + 0.3 * unit(random));
          const std::size_t squeezed = system.springs.size() / 2;
          if (collapse)
          {
            // A spring squeezed to a tenth of its rest length.
            const unsigned int a = system.springs.a[squeezed],
                               b = system.springs.b[squeezed];
            for (unsigned int d = 0; d < 3; ++d)
              system.position[3 * b + d] =
                system.position[3 * a + d]
                + 0.1 * (system.position[3 * b + d] - system.position[3 * a + d]);
          }
          const std::optional<physics::FrequencyBound> kept =
            bound.bound_with_kept_weights(system);
          ASSERT_TRUE(kept.has_value());
          const double highest = kept->omega * kept->omega;
          for (const double factor : {100.0, 3.0, 1.1, 1.001, 0.999, 0.9, 0.2})
          {
            EXPECT_EQ(bound.kept_weights_within(system, factor * highest),
                      highest <= factor * highest)
              << model << ", amplitude " << amplitude << ", collapse " << collapse
              << ", limit " << factor << " x the highest row";
            n_within += factor > 1;
            ++n_compared;
          }
          if (collapse)
            system.position = before;
        }
    }
    EXPECT_EQ(n_compared, 3u * 5u * 2u * 7u);
    EXPECT_EQ(n_within, 3u * 5u * 2u * 4u);
  }


  TEST(StabilityBound, TheCheckSettlesRowsByTheBoundsItsReferenceGives)
  {
    // The inequalities the periodic check rests on, for springs only: every row is at
    // most its isotropic bound, and at most its row at a reference plus 4 rho times
    // its isotropic bound when no spring at it moved by more than rho of its
    // reference length; a spring squeezed below half its rest length is found.
    auto scene = slab_cut_scene("linear springs", 0.01, 0.07, -0.02, -0.07);
    physics::ParticleSystem &system = *scene->system;
    for (unsigned int k = 1; k <= 8; ++k)
      scene->cut(scene->tool->blade(k / 16.0), 0.01 * k);
    physics::StabilityBound bound;
    bound.compute(system);
    const std::vector<double> &weights = bound.row_weights();
    const std::vector<double>  isotropic =
      physics::isotropic_frequency_bounds(system, weights);
    std::vector<unsigned int> spring;
    const std::vector<double> reference = system.position;
    const std::vector<double> reference_rows =
      physics::weighted_frequency_bounds_at(system, reference.data(), weights, spring);
    std::mt19937                           random(5);
    std::uniform_real_distribution<double> unit(-1, 1);
    unsigned int                           n_tight = 0;
    for (const double amplitude : {1e-5, 1e-4, 5e-4})
    {
      system.position = reference;
      for (double &x : system.position)
        x += amplitude * unit(random);
      const std::vector<double> rows = physics::weighted_frequency_bounds_at(
        system, system.position.data(), weights, spring);
      // The largest relative motion of a spring at each particle.
      std::vector<double> rho(system.n_particles(), 0.0);
      for (std::size_t s = 0; s < system.springs.size(); ++s)
      {
        const unsigned int a = system.springs.a[s], b = system.springs.b[s];
        double             moved = 0, length = 0;
        for (unsigned int d = 0; d < 3; ++d)
        {
          const double now  = system.position[3 * b + d] - system.position[3 * a + d];
          const double then = reference[3 * b + d] - reference[3 * a + d];
          moved += (now - then) * (now - then);
          length += then * then;
        }
        for (const unsigned int p : {a, b})
          rho[p] = std::max(rho[p], std::sqrt(moved / length));
      }
      for (unsigned int p = 0; p < system.n_particles(); ++p)
      {
        EXPECT_LE(rows[p], isotropic[p] * (1 + 1e-12)) << "particle " << p;
        const double bound_by_motion = reference_rows[p] + 4 * rho[p] * isotropic[p];
        EXPECT_LE(rows[p], bound_by_motion * (1 + 1e-12)) << "particle " << p;
        n_tight += bound_by_motion < isotropic[p];
      }
    }
    // The motion bound is the tighter one for small motions (else the check would
    // gain nothing over the isotropic rows).
    EXPECT_GT(n_tight, system.n_particles());
    // A squeezed spring is found, and so is a spring that moved past its allowance.
    system.position = reference;
    std::vector<double>       any_motion(system.springs.size(),
                                   std::numeric_limits<double>::infinity());
    std::vector<unsigned int> ends;
    physics::append_ends_of_springs_to_bound_again(
      system, system.position.data(), reference.data(), any_motion, ends);
    EXPECT_TRUE(ends.empty());
    const unsigned int a = system.springs.a[7], b = system.springs.b[7];
    for (unsigned int d = 0; d < 3; ++d)
      system.position[3 * b + d] =
        reference[3 * a + d] + 0.4 * (reference[3 * b + d] - reference[3 * a + d]);
    physics::append_ends_of_springs_to_bound_again(
      system, system.position.data(), reference.data(), any_motion, ends);
    EXPECT_NE(std::find(ends.begin(), ends.end(), b), ends.end());
    ends.clear();
    system.position = reference;
    system.position[3 * b] += 1e-6;
    std::vector<double> little(system.springs.size(), 1e-14);
    physics::append_ends_of_springs_to_bound_again(
      system, system.position.data(), reference.data(), little, ends);
    EXPECT_NE(std::find(ends.begin(), ends.end(), b), ends.end());
    // The isotropic rows are for springs only.
    auto fem = slab_cut_scene("corotated fem", 0.01, 0.07, -0.02, -0.07);
    EXPECT_ANY_THROW(physics::isotropic_frequency_bounds(*fem->system, weights));
  }


  TEST(StabilityBound, KeepsTheHighestParticleAsItsRowsChange)
  {
    // Without a mesh the bound is computed anew at every update; the tree of maxima
    // then names the particle bound_highest_frequency() names.
    auto scene  = slab_cut_scene("linear springs", 0.003, 0.07, 0.003, -0.07);
    auto system = scene->system.get();
    physics::StabilityBound bound;
    bound.compute(*system);
    const physics::FrequencyBound global = physics::bound_highest_frequency(*system);
    EXPECT_EQ(bound.bound().particle, global.particle);
    EXPECT_EQ(bound.bound().spring, global.spring);
    EXPECT_DOUBLE_EQ(bound.bound().omega, global.omega);
    // A particle made light becomes the highest; its neighbours are updated too.
    const unsigned int light = system->n_particles() / 2;
    system->mass[light] *= 1e-3;
    bound.update(*system, {light});
    EXPECT_EQ(bound.bound().particle, physics::bound_highest_frequency(*system).particle);
    EXPECT_EQ(bound.bound().particle, light);
    // A NaN mass wins and is reported, not hidden.
    system->mass[3] = std::numeric_limits<double>::quiet_NaN();
    bound.update(*system, {3});
    EXPECT_TRUE(std::isnan(bound.bound().omega));
  }


  TEST(StabilityBound, MonitorFollowsLocalChangesAndRestartsAtItsNextCheck)
  {
    auto scene  = slab_cut_scene("linear springs", 0.003, 0.07, 0.003, -0.07);
    auto system = scene->system.get();
    physics::BlowUpMonitor monitor(*system, 1.0);
    system->clear_changes();
    // A cut adds particles: the monitor takes them without a global restart, and its
    // next check accepts the state and starts the ledger again.
    const unsigned int before = system->n_particles();
    for (unsigned int k = 1; k <= 8; ++k)
      scene->cut(scene->tool->blade(k / 16.0), 0.01 * k);
    ASSERT_GT(system->n_particles(), before);
    ASSERT_FALSE(system->changed_particles().empty());
    EXPECT_NO_THROW(monitor.note_local_change(
      *system, system->changed_particles(), 8, 0.08, "the cut"));
    system->clear_changes();
    EXPECT_NO_THROW(monitor.check(*system, 9, 0.09));
    // Energy a change adds is caught at the next check, which names the change.
    for (double &v : system->velocity)
      v = 1.0;
    monitor.note_local_change(*system, {0, 1}, 10, 0.1, "the tear");
    try
    {
      monitor.check(*system, 12, 0.12);
      ADD_FAILURE() << "the energy added by the change was not caught";
    }
    catch (const Error &e)
    {
      const std::string message = e.what();
      EXPECT_NE(message.find("since the tear at step 10"), std::string::npos) << message;
    }
    // A non-finite state at a changed particle is caught at once.
    system->position[3 * 5 + 1] = std::numeric_limits<double>::infinity();
    try
    {
      monitor.note_local_change(*system, {4, 5}, 13, 0.13, "the cut");
      ADD_FAILURE() << "an infinite position was not caught";
    }
    catch (const Error &e)
    {
      const std::string message = e.what();
      EXPECT_NE(message.find("right after the cut"), std::string::npos) << message;
      EXPECT_NE(message.find("not a finite number"), std::string::npos) << message;
    }
  }
} // namespace lacerta


namespace lacerta
{
  TEST(StabilityBound, ChangesAreListedOnceAndAResetChangesEverything)
  {
    // However often a particle is reported, it is listed once, so the list never
    // outgrows the particles; after a reset every particle counts as changed, which
    // the bound answers with a full computation.
    auto scene =
      test_support::slab_cut_scene("linear springs", 0.003, 0.07, 0.003, -0.07);
    physics::ParticleSystem  &system = *scene->system;
    std::vector<unsigned int> all(system.n_particles());
    for (unsigned int i = 0; i < all.size(); ++i)
      all[i] = i;
    system.clear_changes();
    for (unsigned int k = 0; k < 5; ++k)
      system.masses_changed(all);
    EXPECT_EQ(system.changed_particles(), all);
    system.clear_changes();
    system.masses_changed({9, 4, 9});
    EXPECT_EQ(system.changed_particles(), (std::vector<unsigned int>{9, 4}));

    physics::StabilityBound bound;
    bound.compute(system);
    const std::vector<double> rest = system.rest_position();
    system.reset(rest);
    EXPECT_TRUE(system.all_particles_changed());
    EXPECT_TRUE(system.changed_particles().empty());
    system.clear_changes();
    EXPECT_FALSE(system.all_particles_changed());
  }
} // namespace lacerta
