// The level of detail following the tool (Multiresolution/Focus follows = tool): the
// focus is where the blade is, and the level of detail is the one a focus path through
// that point would give.
#include <lacerta/cut/cutter.h>
#include <lacerta/cut/tool.h>
#include <lacerta/mt/multiresolution.h>
#include <lacerta/scene/scene.h>

#include <gtest/gtest.h>

#include "mt_test_support.h"
#include <cmath>
#include <sstream>

namespace lacerta
{
  namespace
  {
    /**
     * prm/square_lod.prm (the slab -0.05..0.05 × -0.05..0.05 × 0..0.02) on a coarser
     * box, with @p multiresolution lines added to its subsection and a scalpel held
     * above the slab at x = -0.04 that never touches it.
     */
    std::unique_ptr<scene::Scene>
    slab_scene(const std::string &multiresolution)
    {
      std::ostringstream text;
      text << "include " LACERTA_SCENE_DIR "/square_lod.prm\n"
           << "subsection Mesh\n  subsection Box\n    set Repetitions = 12, 12, 3\n"
           << "  end\nend\n"
           << "subsection Multiresolution\n  set Cache directory =\n"
           << "  set Re-extraction interval = 1\n"
           << multiresolution << "end\n"
           << "subsection Tool\n  set Type = scalpel\n  subsection Scalpel\n"
           << "    set Keyframes = 0, -0.04, 0, 0.045, -0.04, 0, 0.025; 1, -0.04, 0, "
              "0.045, -0.04, 0, 0.025\n  end\nend\n";
      return test_support::scene_from_text("lacerta_mt_focus.prm", text.str());
    }


    /// The mean x of the vertices of the level of detail's smallest tetrahedra (a
    /// tenth of them) away from the fixed edges at x = ±0.05 (whose vertices are
    /// never decimated): where the focus made the level of detail fine.
    double
    fine_region_x(const mesh::TetMesh &m)
    {
      std::vector<std::pair<double, unsigned int>> by_volume;
      for (unsigned int t = 0; t < m.n_tets(); ++t)
      {
        bool fixed = false;
        for (const unsigned int v : m.tet(t))
          fixed = fixed || std::abs(m.vertex(v)[0]) > 0.0499;
        if (!fixed)
          by_volume.emplace_back(m.volume(t), t);
      }
      std::sort(by_volume.begin(), by_volume.end());
      double       sum = 0;
      unsigned int n   = 0;
      for (std::size_t k = 0; k < by_volume.size() / 10; ++k, ++n)
        for (const unsigned int v : m.tet(by_volume[k].second))
          sum += 0.25 * m.vertex(v)[0];
      return sum / n;
    }
  } // namespace


  TEST(MtFocus, TheLevelOfDetailFollowsTheBladeAsAFocusPathThroughItWould)
  {
    auto               follows = slab_scene("  set Focus follows = tool\n");
    std::ostringstream log;
    EXPECT_LT(fine_region_x(follows->active_mesh()), -0.01);

    // The blade moves above the other end of the slab (nothing is cut).
    cut::Blade blade;
    blade.tail = {{0.04, 0.01, 0.045}};
    blade.head = {{0.04, 0.01, 0.025}};
    follows->cutter->move_blade(blade);
    ASSERT_TRUE(follows->update_level_of_detail(0.1, 1, log));
    EXPECT_GT(fine_region_x(follows->active_mesh()), 0.01);

    // The same level of detail as a focus path through the slab's point nearest to the
    // blade (on its top face, z = 0.02, under the blade).
    auto on_path = slab_scene("  set Focus path = t < 0.05 ? -0.04 : 0.04; "
                              "t < 0.05 ? 0 : 0.01; 0.02\n");
    ASSERT_TRUE(on_path->update_level_of_detail(0.1, 1, log));
    EXPECT_EQ(follows->multiresolution->active_vertices(),
              on_path->multiresolution->active_vertices());
  }


  TEST(MtFocus, ABladeThroughTheObjectFocusesOnTheMiddleOfItsPartInside)
  {
    auto       scene = slab_scene("  set Focus follows = tool\n");
    const auto focus = [&](const mesh::Point3 &tail, const mesh::Point3 &head)
    {
      cut::Blade blade;
      blade.tail = tail;
      blade.head = head;
      return scene->multiresolution->focus(0, &blade);
    };
    // Through the slab from z = 0.05 to -0.01: inside from z = 0.02 to 0.
    const mesh::Point3 through = focus({{0.01, 0.02, 0.05}}, {{0.01, 0.02, -0.01}});
    EXPECT_NEAR(through[0], 0.01, 1e-12);
    EXPECT_NEAR(through[1], 0.02, 1e-12);
    EXPECT_NEAR(through[2], 0.01, 1e-12);
    // Beside the slab (x > 0.05), slanting: the slab's point nearest to the blade.
    const mesh::Point3 beside = focus({{0.08, 0, 0.03}}, {{0.06, 0.01, 0.01}});
    EXPECT_NEAR(beside[0], 0.05, 1e-12);
    EXPECT_NEAR(beside[1], 0.01, 1e-9);
    EXPECT_NEAR(beside[2], 0.01, 1e-9);
    // Flat above the top face: the middle of the blade's nearest points, on the face.
    const mesh::Point3 flat = focus({{-0.02, 0.01, 0.03}}, {{0.04, 0.01, 0.03}});
    EXPECT_NEAR(flat[0], 0.01, 1e-3);
    EXPECT_NEAR(flat[1], 0.01, 1e-12);
    EXPECT_NEAR(flat[2], 0.02, 1e-12);
    // Flat, half beyond the slab's edge x = 0.05: the middle of the part above it (to
    // the sampling's 1/64 of the blade).
    const mesh::Point3 half = focus({{0.03, 0, 0.03}}, {{0.09, 0, 0.03}});
    EXPECT_NEAR(half[0], 0.04, 1e-3);
    EXPECT_NEAR(half[2], 0.02, 1e-12);
    // A point blade inside.
    const mesh::Point3 point = focus({{0, 0, 0.01}}, {{0, 0, 0.01}});
    EXPECT_NEAR(point[2], 0.01, 1e-12);
  }
} // namespace lacerta
