// Lacerations on the multiresolution model (doc/lacerations.md, doc/mt-cutting.md): a
// tear cuts the level of detail, its records are replayed on the MT after it, the scene
// stays on the torn level, and every later extraction shows the tear.
#include <lacerta/cut/cutter.h>
#include <lacerta/cut/geometry.h>
#include <lacerta/cut/invariants.h>
#include <lacerta/cut/lacerator.h>
#include <lacerta/cut/tool.h>
#include <lacerta/mt/lod.h>
#include <lacerta/mt/multiresolution.h>
#include <lacerta/physics/particle_system.h>
#include <lacerta/scene/scene.h>

#include <gtest/gtest.h>

#include "mt_test_support.h"
#include "physics_test_support.h"
#include <cmath>
#include <sstream>
#include <string>

namespace lacerta
{
  namespace
  {
    constexpr double density = 1000, youngs = 1e4;
    /// The slab [0,1] x [0,1] x [0,0.25].
    constexpr double volume = 0.25, thickness = 0.25;

    /**
     * The slab of 8 x 8 x 2 boxes on a multiresolution model whose level of detail is
     * the MT's finest (`Uniform/Cell size = 0`), tearing past @p limit (an expression
     * of x, y, z), with the parameter text @p extra appended.
     */
    std::unique_ptr<scene::Scene>
    slab_scene(const std::string &limit, const std::string &extra = "")
    {
      std::ostringstream text;
      text << "subsection Mesh\n  set Source = box\n  subsection Box\n"
           << "    set Lower corner = 0, 0, 0\n    set Upper corner = 1, 1, 0.25\n"
           << "    set Repetitions = 8, 8, 2\n  end\nend\n"
           << "subsection Material\n  set Density = 1000\n  set Youngs modulus = 1e4\n"
           << "  set Maximum elongation = " << limit << "\nend\n"
           << "subsection Multiresolution\n  set Enabled = true\n"
           << "  set Cache directory =\n  set Query = uniform\n"
           << "  subsection Uniform\n    set Cell size = 0\n  end\nend\n"
           << "subsection Laceration\n  set Enabled = true\n  set Threshold h = 3\n"
           << "end\n"
           << extra;
      return test_support::scene_from_text("lacerta_mt_tear.prm", text.str());
    }

    /// Puts every particle at its rest position stretched by @p s along x about
    /// x = @p centre, at rest.
    void
    pull(scene::Scene &scene, const double s, const double centre)
    {
      const mesh::TetMesh &m = scene.active_mesh();
      for (unsigned int i = 0; i < m.n_vertices(); ++i)
      {
        const mesh::Point3 &r             = m.vertex(i);
        scene.system->position[3 * i]     = centre + (1 + s) * (r[0] - centre);
        scene.system->position[3 * i + 1] = r[1];
        scene.system->position[3 * i + 2] = r[2];
        scene.system->velocity[3 * i]     = 0;
        scene.system->velocity[3 * i + 1] = 0;
        scene.system->velocity[3 * i + 2] = 0;
      }
    }

    /// One laceration check of the scene, followed up as the simulator does.
    cut::LacerationStatistics
    check_for_tears(scene::Scene &scene)
    {
      return scene.lacerate(0);
    }

    /// The scene's particle system on its active mesh keeps every invariant.
    void
    expect_scene_invariants(const scene::Scene &scene, const std::string &where)
    {
      EXPECT_EQ(cut::check_invariants(scene.active_mesh(),
                                      *scene.system,
                                      scene.expected_volume(),
                                      scene.integral_of_density),
                "")
        << where;
    }

    /// Area of the faces a cut or tear opened in @p m (both sides), at rest.
    double
    opened_area(const mesh::TetMesh &m)
    {
      double area = 0;
      for (const auto &f : m.get_boundary_faces())
        if (f.boundary_id == cut::cut_boundary_id)
        {
          const auto      &l = mesh::TetMesh::face_vertices[f.face];
          const mesh::Tet &t = m.tet(f.tet);
          area += 0.5
                  * cut::norm(cut::cross(cut::sub(m.vertex(t[l[1]]), m.vertex(t[l[0]])),
                                         cut::sub(m.vertex(t[l[2]]), m.vertex(t[l[0]]))));
        }
      return area;
    }

    /// Area of the boundary faces of @p m that lie on the plane x = @p x0, at rest.
    double
    area_on_plane(const mesh::TetMesh &m, const double x0)
    {
      double area = 0;
      for (const auto &f : m.get_boundary_faces())
      {
        const auto      &l        = mesh::TetMesh::face_vertices[f.face];
        const mesh::Tet &t        = m.tet(f.tet);
        bool             on_plane = true;
        for (const unsigned int k : l)
          on_plane &= std::abs(m.vertex(t[k])[0] - x0) < 1e-9;
        if (on_plane)
          area += 0.5
                  * cut::norm(cut::cross(cut::sub(m.vertex(t[l[1]]), m.vertex(t[l[0]])),
                                         cut::sub(m.vertex(t[l[2]]), m.vertex(t[l[0]]))));
      }
      return area;
    }

    /// Lowest rest y of the faces a cut or tear opened in @p m.
    double
    opened_lowest_y(const mesh::TetMesh &m)
    {
      double lo = 1e300;
      for (const auto &f : m.get_boundary_faces())
        if (f.boundary_id == cut::cut_boundary_id)
          for (const unsigned int k : mesh::TetMesh::face_vertices[f.face])
            lo = std::min(lo, m.vertex(m.tet(f.tet)[k])[1]);
      return lo;
    }

    /**
     * Extracts the MT at cell size @p h from scratch and checks it: a front of the
     * DAG, conforming with positive cells, the slab's volume, masses summing to ∫σ,
     * and @p components pieces. Returns the mesh.
     */
    mesh::TetMesh
    extract(const mt::MultiTriangulation &mt,
            const double                  h,
            const unsigned int            components,
            const std::string            &where)
    {
      mt::Lod lod(mt);
      lod.extract(
        *test_support::make_query("uniform", {{"Cell size", std::to_string(h)}}));
      test_support::expect_front_of_dag(mt, lod);
      mesh::TetMesh m      = lod.make_mesh(lod.active_vertices(), "extraction");
      const auto    system = test_support::make_system(m, density, youngs);
      EXPECT_EQ(cut::check_invariants(m, *system, volume, density * volume), "")
        << where << ", cell size " << h;
      EXPECT_EQ(cut::count_components(m), components) << where << ", cell size " << h;
      return m;
    }

    /// Weak in the column of cells 0.375 < x < 0.5 near the edge y = 1 only: under a
    /// stretch of 0.4 its springs along x pass their limit for y > 0.78 and half of it
    /// for y > 0.5 (tests/unit/cut_laceration.cc).
    const std::string weak_column = "abs(x - 0.4375) < 0.07 ? 0.3 + 2*(1 - y)^2 : 10";
    const std::string weak_near_one_edge = "0.3 + 2*(1 - y)^2";
  } // namespace


  TEST(MtTear, TwoPullsTearTheMtAndEveryLevelShowsIt)
  {
    auto                          scene = slab_scene(weak_column);
    const mt::MultiTriangulation &mt    = scene->multiresolution->multi_triangulation();
    ASSERT_EQ(scene->active_mesh().n_tets(), 640u);
    const double slab_area = test_support::boundary_area(scene->active_mesh());
    // Every extraction before the tear (the middle and coarsest levels' areas).
    const double middle_area0 =
      test_support::boundary_area(extract(mt, 0.3, 1, "before the tear"));
    const mesh::TetMesh coarsest0 = extract(mt, 1000, 1, "before the tear");
    ASSERT_LT(coarsest0.n_tets(), 20u);

    // First pull: the tear starts at the weak edge y = 1 and stops inside.
    pull(*scene, 0.4, 0.4375);
    const cut::LacerationStatistics first = check_for_tears(*scene);
    ASSERT_TRUE(first.torn);
    ASSERT_FALSE(first.complete);
    ASSERT_TRUE(scene->cut_pending());
    expect_scene_invariants(*scene, "after the first tear, on the level of detail");
    // The tear's area at rest, from the faces it opened (both sides), against the
    // section it crossed: from y = 1 down to where it stopped, through the thickness.
    const double torn = 0.5 * opened_area(scene->active_mesh());
    const double stop = opened_lowest_y(scene->active_mesh());
    EXPECT_GT(stop, 0.3);
    EXPECT_LT(stop, 0.7);
    EXPECT_NEAR(torn, thickness * (1 - stop), 0.15 * thickness * (1 - stop));

    // The MT replays the tear after it; the scene stays on the torn level of detail.
    const unsigned int n_particles = scene->system->n_particles();
    const auto         update      = scene->update_multiresolution_after_cut(0.5);
    ASSERT_TRUE(update.has_value());
    EXPECT_FALSE(scene->cut_pending());
    EXPECT_GT(update->update.split_fragments, 0u);
    EXPECT_GT(update->update.new_vertices, 0u);
    EXPECT_EQ(update->pieces, 1u);
    EXPECT_EQ(scene->system->n_particles(), n_particles);
    EXPECT_NO_THROW(mt.check("torn MT"));
    expect_scene_invariants(*scene, "after the MT update");
    // Every extraction, from the finest to the coarsest, shows the whole tear: the
    // slab's faces are flat, so only the tear changes the boundary's area.
    const mesh::TetMesh finest = extract(mt, 0, 1, "after the first pull");
    const double        opened = test_support::boundary_area(finest) - slab_area;
    EXPECT_NEAR(opened, 2 * torn, 1e-9);
    EXPECT_NEAR(test_support::boundary_area(scene->active_mesh()) - slab_area,
                opened,
                1e-12);
    EXPECT_NEAR(test_support::boundary_area(extract(mt, 0.3, 1, "after the first pull"))
                  - middle_area0,
                opened,
                1e-9);
    extract(mt, 1000, 1, "after the first pull");
    ASSERT_FALSE(::testing::Test::HasFailure());

    // The lacerator knows its tear's particles: on the tear's surface (rest x near the
    // plane x = 0.4375, above where it stopped), and no others.
    unsigned int n_found = 0;
    for (unsigned int v = 0; v < scene->system->n_particles(); ++v)
      if (scene->lacerator->created_by_laceration(v))
      {
        ++n_found;
        const mesh::Point3 &r = scene->active_mesh().vertex(v);
        EXPECT_NEAR(r[0], 0.4375, 0.07) << "particle " << v;
        EXPECT_GT(r[1], stop - 0.2) << "particle " << v;
      }
    EXPECT_GT(n_found, 20u);
    // At the same stretch nothing tears again (the torn surface's springs do not seed
    // a second tear).
    pull(*scene, 0.4, 0.4375);
    EXPECT_FALSE(check_for_tears(*scene).torn);

    // Second pull, about the tear's plane: the same laceration goes on from its tip,
    // with a cutter built there on the MT's mesh, down to the far rim.
    pull(*scene, 1.5, 0.4375);
    const cut::LacerationStatistics second = check_for_tears(*scene);
    ASSERT_TRUE(second.torn);
    EXPECT_TRUE(second.continued);
    EXPECT_TRUE(second.complete);
    EXPECT_GT(second.cut_tets, 0u);
    EXPECT_EQ(scene->lacerator->n_tears(), 2u);
    expect_scene_invariants(*scene, "after the second tear, on the level of detail");
    const auto again = scene->update_multiresolution_after_cut(1.0);
    ASSERT_TRUE(again.has_value());
    EXPECT_NO_THROW(mt.check("torn MT, continued"));
    expect_scene_invariants(*scene, "after the MT update of the continued tear");
    // The continuation's cutter takes the tear's particles on its plane as its crack,
    // so it opens the cells at the old tip too. The slab is in two pieces on the level
    // of detail and at every level, and the finest level's boundary has grown by
    // exactly the two faces of the section by the plane (1 x 0.25 each), nothing
    // more: no flap at the old tip.
    EXPECT_EQ(cut::count_components(scene->active_mesh()), 2u);
    const mesh::TetMesh through        = extract(mt, 0, 2, "after the second pull");
    const double        through_opened = test_support::boundary_area(through) - slab_area;
    EXPECT_NEAR(through_opened, 2 * thickness, 1e-9);
    EXPECT_NEAR(area_on_plane(through, 0.4375), 2 * thickness, 1e-9);
    for (const double h : {0.3, 0.5, 1000.0})
      extract(mt, h, 2, "after the second pull");
  }


  TEST(MtTear, UniformStretchTearsEveryLevelThrough)
  {
    auto                          scene = slab_scene("0.3");
    const mt::MultiTriangulation &mt    = scene->multiresolution->multi_triangulation();
    const double slab_area = test_support::boundary_area(scene->active_mesh());
    pull(*scene, 0.4, 0.5);
    const cut::LacerationStatistics tear = check_for_tears(*scene);
    ASSERT_TRUE(tear.torn);
    ASSERT_TRUE(tear.complete);
    EXPECT_EQ(cut::count_components(scene->active_mesh()), 2u);
    const double torn = 0.5 * opened_area(scene->active_mesh());
    EXPECT_NEAR(torn, thickness, 0.05 * thickness);
    const auto update = scene->update_multiresolution_after_cut(0.5);
    ASSERT_TRUE(update.has_value());
    EXPECT_EQ(update->pieces, 2u);
    EXPECT_NO_THROW(mt.check("torn MT"));
    expect_scene_invariants(*scene, "after the MT update");
    // Two pieces at every level; the finest has both sides of the whole section.
    const mesh::TetMesh finest = extract(mt, 0, 2, "torn through");
    EXPECT_NEAR(test_support::boundary_area(finest) - slab_area, 2 * torn, 0.05 * torn);
    for (const double h : {0.2, 0.3, 0.5, 1000.0})
      extract(mt, h, 2, "torn through");
  }


  TEST(MtTear, LaceratedThenCutKeepsEveryInvariant)
  {
    // A scalpel across the slab along y = 0.2, through the thickness, after the tear:
    // from x = -0.5 to 2 over a second (the slab spans -0.2 .. 1.2 stretched).
    auto scene =
      slab_scene(weak_near_one_edge,
                 "subsection Tool\n  set Type = scalpel\n  subsection Scalpel\n"
                 "    set Keyframes = 0, -0.5, 0.2, 0.5, -0.5, 0.2, -0.25; "
                 "1, 2, 0.2, 0.5, 2, 0.2, -0.25\n  end\nend\n");
    const mt::MultiTriangulation &mt = scene->multiresolution->multi_triangulation();
    pull(*scene, 0.4, 0.5);
    const cut::LacerationStatistics tear = check_for_tears(*scene);
    ASSERT_TRUE(tear.torn);
    ASSERT_FALSE(tear.complete);
    ASSERT_TRUE(scene->update_multiresolution_after_cut(0).has_value());
    EXPECT_NO_THROW(mt.check("torn MT"));
    expect_scene_invariants(*scene, "after the tear");
    ASSERT_FALSE(::testing::Test::HasFailure());

    const unsigned int n_steps = 30;
    for (unsigned int k = 1; k <= n_steps; ++k)
    {
      scene->cut(scene->tool->blade(double(k) / n_steps), 0);
      expect_scene_invariants(*scene, "scalpel step " + std::to_string(k));
      ASSERT_FALSE(::testing::Test::HasFailure());
    }
    ASSERT_TRUE(scene->cutter->active_tets().empty());
    // The scalpel separated the strip y < 0.2 (at rest); the tear did not reach it.
    EXPECT_EQ(cut::count_components(scene->active_mesh()), 2u);
    const auto update = scene->update_multiresolution_after_cut(1);
    ASSERT_TRUE(update.has_value());
    EXPECT_EQ(update->pieces, 2u);
    EXPECT_NO_THROW(mt.check("torn and cut MT"));
    expect_scene_invariants(*scene, "after the MT update");
    for (const double h : {0.0, 0.3, 1000.0})
      extract(mt, h, 2, "torn and cut");
    // The lacerator sees the new mesh and stays consistent.
    check_for_tears(*scene);
    expect_scene_invariants(*scene, "after a second check");
  }
} // namespace lacerta
