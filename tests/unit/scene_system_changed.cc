// The one event of a change of the particle system (Scene::system_changed): every cut,
// tear and new level of detail is announced once, with its cause, after the scene has
// followed it. The MT update after a stroke changes no particle: it has its own event
// (Scene::multi_triangulation_cut).
#include <lacerta/base/exceptions.h>
#include <lacerta/cut/lacerator.h>
#include <lacerta/cut/tool.h>
#include <lacerta/mt/multiresolution.h>
#include <lacerta/physics/particle_system.h>
#include <lacerta/scene/scene.h>

#include <gtest/gtest.h>

#include "mt_test_support.h"
#include <sstream>
#include <vector>

namespace lacerta
{
  namespace
  {
    using Cause = scene::SystemChange::Cause;

    /// prm/square_lod.prm, coarser, with a scalpel across it in the first second.
    std::unique_ptr<scene::Scene>
    slab_with_scalpel(const bool multiresolution)
    {
      std::ostringstream text;
      text << "include " LACERTA_SCENE_DIR "/square_lod.prm\n"
           << "subsection Mesh\n  subsection Box\n    set Repetitions = 10, 10, 2\n"
           << "  end\nend\n"
           << "subsection Multiresolution\n  set Enabled = "
           << (multiresolution ? "true" : "false") << "\n  set Cache directory =\nend\n"
           << "subsection Tool\n  set Type = scalpel\n  subsection Scalpel\n"
           << "    set Keyframes = 0, 0.003, 0.07, 0.03, 0.003, 0.07, -0.01; "
              "1, 0.003, -0.07, 0.03, 0.003, -0.07, -0.01\n  end\nend\n";
      return test_support::scene_from_text("lacerta_system_changed.prm", text.str());
    }

    /// What a subscriber heard.
    struct Heard
    {
      Cause        cause;
      double       time;
      std::size_t  copies;
      unsigned int particles;
    };
  } // namespace


  TEST(SceneSystemChanged, EveryChangeIsOneEventWithItsCauseAfterTheSceneFollowedIt)
  {
    auto               scene = slab_with_scalpel(true);
    std::vector<Heard> heard;
    scene->system_changed.connect(
      [&](const scene::SystemChange &c)
      {
        heard.push_back(
          {c.cause, c.time, c.copied_particles().size(), scene->system->n_particles()});
        // The scene's own subscriber ran first: the cutter works on the current mesh.
        ASSERT_TRUE(scene->cutter);
        // Only a change of level removes (and so renumbers) particles.
        EXPECT_EQ(c.particle_renumbering != nullptr, c.cause == Cause::level_of_detail);
        EXPECT_FALSE(c.describe().empty());
        // What the change did comes with it, for its cause only.
        EXPECT_EQ(c.cut != nullptr, c.cause == Cause::cut);
        EXPECT_EQ(c.tear != nullptr, c.cause == Cause::laceration);
      });
    std::vector<scene::MultiresolutionCut> mt_cuts;
    scene->multi_triangulation_cut.connect(
      [&](const scene::MultiresolutionCut &c)
      {
        mt_cuts.push_back(c);
        EXPECT_EQ(c.n_tets, scene->active_mesh().n_tets());
      });
    const unsigned int n_steps = 60;
    unsigned int       changes = 0;
    for (unsigned int k = 1; k <= n_steps; ++k)
    {
      const std::size_t            before = heard.size();
      const cut::CutStepStatistics s =
        scene->cut(scene->tool->blade(double(k) / n_steps), 0.01 * k);
      ASSERT_EQ(heard.size(), before + (s.changed ? 1 : 0)) << "step " << k;
      if (!s.changed)
        continue;
      ++changes;
      EXPECT_EQ(heard.back().cause, Cause::cut);
      EXPECT_EQ(heard.back().time, 0.01 * k);
      EXPECT_EQ(heard.back().copies, s.copied_particles.size());
      EXPECT_EQ(heard.back().particles, scene->system->n_particles());
    }
    ASSERT_GT(changes, 0u);
    ASSERT_TRUE(scene->cutter->active_tets().empty());

    // After the stroke: the MT update, one event of its own, no change of the system.
    const std::size_t before = heard.size();
    EXPECT_TRUE(mt_cuts.empty());
    ASSERT_TRUE(scene->update_multiresolution_after_cut(1.0).has_value());
    ASSERT_EQ(heard.size(), before);
    ASSERT_EQ(mt_cuts.size(), 1u);
    EXPECT_EQ(mt_cuts.back().time, 1.0);
    // Nothing more to update: no event.
    EXPECT_FALSE(scene->update_multiresolution_after_cut(1.0).has_value());
    EXPECT_EQ(heard.size(), before);
    EXPECT_EQ(mt_cuts.size(), 1u);
    // A re-extraction is one event if it changed the system, none otherwise.
    std::ostringstream log;
    const bool         changed = scene->update_level_of_detail(1.0, 2000000, log);
    ASSERT_EQ(heard.size(), before + (changed ? 1 : 0));
    if (changed)
    {
      EXPECT_EQ(heard.back().cause, Cause::level_of_detail);
    }
  }


  TEST(SceneSystemChanged, NoToolOrNoLacerationsIsAnError)
  {
    std::ostringstream text;
    text << "include " LACERTA_SCENE_DIR "/square_pull.prm\n";
    auto scene = test_support::scene_from_text("lacerta_no_tool.prm", text.str());
    EXPECT_THROW(scene->cut(cut::Blade(), 0), Error);
    EXPECT_THROW(scene->lacerate(0), Error);
  }
} // namespace lacerta
