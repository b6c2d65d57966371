// Cuts on the Multi-Triangulation (Section 5.1): a level of detail cut by the Cutter,
// the MT updated from the cutter's records (replayed, nodes pinned), and every
// extraction checked afterwards.
#include <lacerta/cut/cutter.h>
#include <lacerta/cut/invariants.h>
#include <lacerta/mesh/vtk_reader.h>
#include <lacerta/mt/builder.h>
#include <lacerta/mt/lod.h>
#include <lacerta/mt/lod_query.h>
#include <lacerta/mt/mt_cutter.h>
#include <lacerta/physics/assembly.h>
#include <lacerta/physics/particle_system.h>

#include <deal.II/base/function.h>

#include <gtest/gtest.h>

#include "cut_split_support.h"
#include "mt_test_support.h"
#include "physics_test_support.h"
#include <algorithm>
#include <map>
#include <random>
#include <set>

namespace lacerta
{
  namespace
  {
    using cut::Blade;
    using mesh::Tet;

    constexpr double density = 1000;

    using test_support::boundary_area;
    using test_support::expect_front_of_dag;
    using test_support::make_query;

    std::unique_ptr<mt::LodQuery>
    uniform(const double h)
    {
      return make_query("uniform", {{"Cell size", std::to_string(h)}});
    }

    /// A unit box of 5^3 hexahedra split into tetrahedra, interior vertices jittered.
    const mesh::TetMesh &
    jittered_box()
    {
      static const mesh::TetMesh mesh =
        test_support::distorted_box(5, 0.25, dealii::Point<3>(1, 1, 1));
      return mesh;
    }

    /// A vertical blade through the whole box at (x, y), spanning z from -0.5 to 1.5.
    Blade
    vertical(const double x, const double y)
    {
      return {{{x, y, 1.5}}, {{x, y, -0.5}}};
    }

    /// A mesh with its particle system and a cutter, recording its sweeps.
    struct CutMesh
    {
      mesh::TetMesh                            mesh;
      std::unique_ptr<physics::ParticleSystem> system;
      dealii::Functions::ConstantFunction<3>   sigma{density};
      dealii::Functions::ConstantFunction<3>   youngs{1e4};
      double                                   integral = density;
      std::vector<cut::CutRecord>              records;
      std::unique_ptr<cut::Cutter>             cutter;

      CutMesh(mesh::TetMesh m, const Blade &start)
          : mesh(std::move(m))
          , system(test_support::make_system(mesh, density, 1e4))
      {
        integral = physics::integrate_over_mesh(mesh, sigma);
        cutter   = std::make_unique<cut::Cutter>(
          mesh, *system, sigma, youngs, integral, cut::Cutter::Parameters(), start);
        cutter->set_recorder(&records);
      }

      /// Moves the blade through @p path, @p steps steps per segment.
      void
      stroke(const std::vector<Blade> &path, const unsigned int steps)
      {
        cut::test_support::stroke(*cutter,
                                  path,
                                  steps,
                                  [](std::size_t,
                                     unsigned int,
                                     const cut::CutStepStatistics &) { return true; });
      }
    };

    /**
     * Extracts @p query from scratch and checks it: conforming with positive cells,
     * the volume of the box, masses summing to ∫σ, @p components pieces (0: any), the
     * DAG front, and every live tet a cut created (ids from @p first_cut_tet) active.
     * Returns the mesh.
     */
    mesh::TetMesh
    check_extraction(const mt::MultiTriangulation &mt,
                     const mt::LodQuery           &query,
                     const unsigned int            components,
                     const std::string            &where,
                     const std::uint32_t           first_cut_tet)
    {
      mt::Lod lod(mt);
      lod.extract(query);
      expect_front_of_dag(mt, lod);
      unsigned int missing = 0;
      for (std::uint32_t t = first_cut_tet; t < mt.n_tets(); ++t)
        missing += mt.is_live(t) && !lod.is_active(t);
      EXPECT_EQ(missing, 0u) << where << ": cut tetrahedra left out";
      const auto    vertices = lod.active_vertices();
      mesh::TetMesh m        = lod.make_mesh(vertices, "extraction");
      const auto    system   = test_support::make_system(m, density, 1e4);
      EXPECT_EQ(cut::check_invariants(m, *system, 1.0, density), "") << where;
      if (components > 0)
      {
        EXPECT_EQ(cut::count_components(m), components) << where;
      }
      return m;
    }

    /// Uniform queries from finest to coarsest and focus queries around the cut.
    void
    check_all_levels(const mt::MultiTriangulation &mt,
                     const unsigned int            components,
                     const std::uint32_t           first_cut_tet)
    {
      for (const double h : {0.0, 0.2, 0.35, 0.6, 1000.0})
        check_extraction(
          mt, *uniform(h), components, "uniform " + std::to_string(h), first_cut_tet);
      for (const double radius : {0.1, 0.3})
      {
        auto query =
          make_query("focus",
                     {{"Radius", std::to_string(radius)}, {"Cell size growth", "0.5"}});
        for (const mesh::Point3 &focus :
             {mesh::Point3{{0.5, 0.5, 0.5}}, mesh::Point3{{0.1, 0.8, 0.3}}})
        {
          query->set_focus(focus);
          check_extraction(
            mt, *query, components, "focus " + std::to_string(radius), first_cut_tet);
        }
      }
    }

    /// The sorted vertex quadruples of @p tets, through @p id_of.
    template <typename Tets, typename Map>
    std::set<Tet>
    sorted_tets(const Tets &tets, const Map &id_of)
    {
      std::set<Tet> result;
      for (const auto &t : tets)
      {
        Tet mapped;
        for (unsigned int i = 0; i < 4; ++i)
          mapped[i] = id_of(t[i]);
        std::sort(mapped.begin(), mapped.end());
        result.insert(mapped);
      }
      return result;
    }

    /// Cuts the level of detail @p query selects with @p path and updates the MT.
    struct LodCut
    {
      mt::MultiTriangulation     mt;
      mt::Lod                    lod;
      std::unique_ptr<CutMesh>   cut;
      std::vector<std::uint32_t> mt_vertex_of;
      std::uint32_t              first_cut_tet = 0;
      mt::MtCutter::Statistics   statistics;

      LodCut(const mt::LodQuery       &query,
             const std::vector<Blade> &path,
             unsigned int              steps)
          : mt(mt::build_multi_triangulation(jittered_box(), mt::BuilderParameters()))
          , lod(mt)
      {
        lod.extract(query);
        mt_vertex_of = lod.active_vertices();
        cut = std::make_unique<CutMesh>(lod.make_mesh(mt_vertex_of, "lod"), path[0]);
        cut->stroke(path, steps);
        first_cut_tet = mt.n_tets();
        mt::MtCutter cutter(mt);
        statistics = cutter.apply(cut->records, mt_vertex_of, lod);
      }

      /// The level of detail that followed the cut is the cutter's mesh, tetrahedron
      /// for tetrahedron, and a valid front of the DAG.
      void
      expect_lod_is_the_cut_mesh() const
      {
        expect_front_of_dag(mt, lod);
        ASSERT_EQ(mt_vertex_of.size(), cut->mesh.n_vertices());
        for (unsigned int v = 0; v < cut->mesh.n_vertices(); ++v)
          ASSERT_EQ(mt.vertices[mt_vertex_of[v]], cut->mesh.vertex(v)) << v;
        std::vector<mesh::Tet> active;
        for (const std::uint32_t t : lod.active_tets())
          active.push_back(mt.tets[t]);
        EXPECT_EQ(sorted_tets(active, [](const unsigned int v) { return v; }),
                  sorted_tets(cut->mesh.get_tets(),
                              [&](const unsigned int v) { return mt_vertex_of[v]; }));
      }
    };
  } // namespace


  TEST(MtCut, CutAtTheFinestLevelIsKeptByEveryExtraction)
  {
    LodCut c(*uniform(0), {vertical(-0.2, 0.43), vertical(1.2, 0.47)}, 12);
    EXPECT_EQ(cut::count_components(c.cut->mesh), 2u);
    EXPECT_NO_THROW(c.mt.check("cut MT"));
    c.expect_lod_is_the_cut_mesh();
    EXPECT_GT(c.statistics.split_fragments, 10u);
    EXPECT_GT(c.statistics.created_tets, c.statistics.cut_tets);
    EXPECT_GT(c.statistics.pinned_applied, 0u);
    check_all_levels(c.mt, 2, c.first_cut_tet);
    // The coarsest extraction is coarse away from the cut, and has the cutter's
    // pieces: the box's faces are flat at every level.
    const mesh::TetMesh coarsest =
      check_extraction(c.mt, *uniform(1000), 2, "coarsest", c.first_cut_tet);
    EXPECT_LT(coarsest.n_tets(), c.cut->mesh.n_tets());
    const auto a = cut::component_volumes(coarsest),
               b = cut::component_volumes(c.cut->mesh);
    ASSERT_EQ(a.size(), b.size());
    for (std::size_t k = 0; k < a.size(); ++k)
      EXPECT_NEAR(a[k], b[k], 1e-9);
  }


  TEST(MtCut, CutAtACoarseLevelStaysCoarseWhereItPassed)
  {
    const std::vector<Blade> path = {vertical(-0.2, 0.43), vertical(1.2, 0.47)};
    LodCut                   c(*uniform(0.5), path, 12);
    EXPECT_EQ(cut::count_components(c.cut->mesh), 2u);
    EXPECT_NO_THROW(c.mt.check("cut MT"));
    c.expect_lod_is_the_cut_mesh();
    check_all_levels(c.mt, 2, c.first_cut_tet);
    // The full-resolution mesh cut directly by the same strokes: the same pieces
    // within what snapping to coarse and fine edges moves.
    CutMesh direct(jittered_box(), path[0]);
    direct.stroke(path, 12);
    const mesh::TetMesh finest =
      check_extraction(c.mt, *uniform(0), 2, "finest", c.first_cut_tet);
    EXPECT_GT(finest.n_tets(), c.cut->mesh.n_tets());
    const auto a = cut::component_volumes(finest),
               b = cut::component_volumes(direct.mesh),
               d = cut::component_volumes(c.cut->mesh);
    ASSERT_EQ(a.size(), 2u);
    ASSERT_EQ(b.size(), 2u);
    for (std::size_t k = 0; k < 2; ++k)
    {
      EXPECT_NEAR(a[k], d[k], 1e-9);
      EXPECT_NEAR(a[k], b[k], 0.01);
    }
    // The cut surface: the boundary minus the box's six faces, two sheets.
    EXPECT_NEAR(boundary_area(finest) - 6, 2.0, 0.05);
  }


  TEST(MtCut, PartialCutKeepsEveryLevelInOnePiece)
  {
    // A crack that ends inside the body: every level of detail keeps it, valid and in
    // one piece.
    LodCut c(*uniform(0.35), {vertical(-0.2, 0.52), vertical(0.55, 0.5)}, 8);
    EXPECT_EQ(cut::count_components(c.cut->mesh), 1u);
    EXPECT_GT(c.statistics.cut_tets, 0u);
    EXPECT_GT(c.statistics.new_vertices, 0u);
    EXPECT_NO_THROW(c.mt.check("cut MT"));
    c.expect_lod_is_the_cut_mesh();
    check_all_levels(c.mt, 1, c.first_cut_tet);
  }


  TEST(MtCut, SecondCutAfterAFirstOneKeepsEveryLevelValid)
  {
    // Two complete strokes at different levels of detail: three pieces everywhere.
    LodCut  c(*uniform(0), {vertical(-0.2, 0.3), vertical(1.2, 0.32)}, 10);
    mt::Lod second(c.mt);
    second.extract(*uniform(0.35));
    std::vector<std::uint32_t> mt_vertex_of = second.active_vertices();
    CutMesh cut2(second.make_mesh(mt_vertex_of, "lod"), vertical(-0.2, 0.7));
    cut2.stroke({vertical(-0.2, 0.7), vertical(1.2, 0.66)}, 10);
    EXPECT_EQ(cut::count_components(cut2.mesh), 3u);
    mt::MtCutter cutter(c.mt);
    const auto   statistics = cutter.apply(cut2.records, mt_vertex_of, second);
    EXPECT_GT(statistics.cut_tets, 0u);
    EXPECT_NO_THROW(c.mt.check("twice cut MT"));
    expect_front_of_dag(c.mt, second);
    check_all_levels(c.mt, 3, c.first_cut_tet);
  }


  TEST(MtCut, RandomStrokesAtRandomLevelsKeepEveryLevelValid)
  {
    std::uniform_real_distribution<double> u(0.15, 0.85), angle(0, 3.14159), h(0, 0.6);
    for (unsigned int seed = 0; seed < 4; ++seed)
    {
      std::mt19937     rng(300 + seed);
      const double     phi = angle(rng), cx = u(rng), cy = u(rng);
      const cut::Point dir{{std::cos(phi), std::sin(phi), 0}};
      LodCut           c(*uniform(h(rng)),
               {vertical(cx - dir[0], cy - dir[1]), vertical(cx + dir[0], cy + dir[1])},
               6 + 2 * seed);
      ASSERT_NO_THROW(c.mt.check("cut MT")) << "seed " << seed;
      c.expect_lod_is_the_cut_mesh();
      // Every level has the cutter's pieces: a straight stroke through makes two.
      EXPECT_EQ(cut::count_components(c.cut->mesh), 2u) << "seed " << seed;
      check_all_levels(c.mt, cut::count_components(c.cut->mesh), c.first_cut_tet);
      ASSERT_FALSE(::testing::Test::HasFailure()) << "seed " << seed;
    }
  }


  TEST(MtCut, TheLevelOfDetailThatFollowedTheCutUpdatesLikeAFreshOne)
  {
    // The cut LOD's frontier bookkeeping stays right: updated incrementally from it,
    // every query selects the same tets as an extraction from scratch.
    LodCut c(*make_query("focus", {{"Radius", "0.2"}, {"Cell size growth", "0.5"}}),
             {vertical(-0.2, 0.43), vertical(1.2, 0.47)},
             12);
    for (const double h : {0.0, 0.6, 0.2, 1000.0, 0.0})
    {
      const auto query = uniform(h);
      c.lod.extract(*query);
      mt::Lod fresh(c.mt);
      fresh.extract(*query);
      std::vector<std::uint32_t> a = c.lod.active_tets(), b = fresh.active_tets();
      std::sort(a.begin(), a.end());
      std::sort(b.begin(), b.end());
      EXPECT_EQ(a, b) << "cell size " << h;
      expect_front_of_dag(c.mt, c.lod);
    }
  }


  TEST(MtCut, ExtractionsAfterACutBringInOnlyVerticesOfTheUncutLevels)
  {
    LodCut            c(*uniform(0.5), {vertical(-0.2, 0.43), vertical(1.2, 0.47)}, 12);
    const std::size_t first = c.mt.first_cut_vertex();
    ASSERT_GT(c.mt.cut_origin.size(), 0u);
    // Coarse to fine and back: every vertex brought in by either extraction lies in a
    // tet that was active before, and none is a cut's (the cut stays).
    mt::Lod lod(c.mt);
    lod.extract(*uniform(1000));
    unsigned int located = 0;
    for (const double size : {0.0, 1000.0, 0.2})
    {
      const auto              before = lod.active_vertices();
      std::set<std::uint32_t> active_before(lod.active_tets().begin(),
                                            lod.active_tets().end());
      lod.extract(*uniform(size));
      for (const auto v : lod.active_vertices())
        if (!std::binary_search(before.begin(), before.end(), v))
        {
          EXPECT_LT(v, first) << "a cut's vertex came in";
          const auto [t, lambda] = lod.locate_in_previous(v);
          EXPECT_TRUE(active_before.count(t)) << "vertex " << v;
          EXPECT_GT(*std::min_element(lambda.begin(), lambda.end()), -0.1) << v;
          ++located;
        }
    }
    EXPECT_GT(located, 0u);
  }


  namespace
  {
    /// The sagging kidney of prm/kidney_cut.prm at a point at rest: its poles droop
    /// (the body hangs at the hilum, x = 0) and it is sheared a little along x.
    mesh::Point3
    sagged(const mesh::Point3 &r)
    {
      return {{r[0] + 0.05 * r[2], r[1], r[2] - 3.0 * r[0] * r[0]}};
    }
  } // namespace


  TEST(MtCut, CompleteCutOfTheSaggingKidneyIsKeptAtEveryLevel)
  {
    // A curved organ, deformed, cut by a blade in world coordinates: the rest cut
    // surface is curved (the sag maps the blade's plane x = 0.032 onto a sheared
    // surface), unlike the straight cuts of the undeformed box above. The blade spans
    // the kidney's thickness and crosses it from outside to outside (y from -0.045 to
    // 0.045) in steps of 1.8 mm, as the complete stroke of prm/kidney_cut.prm does.
    const mesh::TetMesh kidney =
      mesh::read_vtk_unstructured_grid(LACERTA_TEST_DATA_DIR "/kidney.vtu");
    mt::MultiTriangulation mt = mt::build_multi_triangulation(kidney, {});
    auto                   at_the_cut =
      make_query("focus", {{"Radius", "0.02"}, {"Cell size growth", "0.5"}});
    at_the_cut->set_focus({{0.032, 0, 0}});
    auto elsewhere =
      make_query("focus", {{"Radius", "0.02"}, {"Cell size growth", "0.5"}});
    elsewhere->set_focus({{-0.03, 0, 0.01}});
    const auto finest = uniform(0), coarsest = uniform(1000);
    const std::vector<std::pair<std::string, const mt::LodQuery *>> queries = {
      {"finest", finest.get()},
      {"coarsest", coarsest.get()},
      {"focus at the cut", at_the_cut.get()},
      {"focus elsewhere", elsewhere.get()}};
    // Each level's volume before the cut: the cut must keep it.
    std::map<std::string, double> uncut_volume;
    for (const auto &[name, query] : queries)
    {
      mt::Lod lod(mt);
      lod.extract(*query);
      uncut_volume[name] = lod.make_mesh(lod.active_vertices(), name).total_volume();
    }

    double smallest_volume = 1e300, largest_volume = 0;
    for (const auto &[name, volume] : uncut_volume)
    {
      smallest_volume = std::min(smallest_volume, volume);
      largest_volume  = std::max(largest_volume, volume);
    }

    mt::Lod lod(mt);
    lod.extract(*at_the_cut);
    const auto blade = [](const double y) -> Blade {
      return {{{0.032, y, 0.05}}, {{0.032, y, -0.05}}};
    };
    std::vector<std::uint32_t> mt_vertex_of = lod.active_vertices();
    CutMesh                    cut(lod.make_mesh(mt_vertex_of, "lod"), blade(-0.045));
    for (unsigned int v = 0; v < cut.mesh.n_vertices(); ++v)
    {
      const mesh::Point3 x = sagged(cut.mesh.vertex(v));
      for (unsigned int d = 0; d < 3; ++d)
        cut.system->position[3 * v + d] = x[d];
    }
    cut.stroke({blade(-0.045), blade(0.045)}, 50);
    ASSERT_TRUE(cut.cutter->active_tets().empty());
    const std::vector<double> cutter_pieces = cut::component_volumes(cut.mesh);
    ASSERT_EQ(cutter_pieces.size(), 2u);
    // The pole beyond the cut: about 8 % of the kidney.
    EXPECT_GT(cutter_pieces[0], 0.05 * cutter_pieces[1]);
    EXPECT_LT(cutter_pieces[0], 0.15 * cutter_pieces[1]);

    const std::uint32_t first_cut_tet = mt.n_tets();
    mt::MtCutter        cutter(mt);
    const auto          statistics = cutter.apply(cut.records, mt_vertex_of, lod);
    EXPECT_GT(statistics.split_fragments, 0u);
    EXPECT_NO_THROW(mt.check("cut kidney MT"));
    expect_front_of_dag(mt, lod);

    for (const auto &[name, query] : queries)
    {
      mt::Lod extraction(mt);
      extraction.extract(*query);
      expect_front_of_dag(mt, extraction);
      const mesh::TetMesh m = extraction.make_mesh(extraction.active_vertices(), name);
      unsigned int        missing = 0;
      for (std::uint32_t t = first_cut_tet; t < mt.n_tets(); ++t)
        missing += mt.is_live(t) && !extraction.is_active(t);
      EXPECT_EQ(missing, 0u) << name << ": cut tetrahedra left out";
      // The cut region keeps the resolution it was cut at, the rest is the query's:
      // the volume lies between the levels' (decimating moves the boundary).
      const double volume = m.total_volume();
      EXPECT_GT(volume, (1 - 1e-3) * smallest_volume) << name;
      EXPECT_LT(volume, (1 + 1e-3) * largest_volume) << name;
      // Conforming, positive cells, masses summing to ∫σ.
      const auto system = test_support::make_system(m, density, 1e4);
      EXPECT_EQ(cut::check_invariants(m, *system, volume, density * volume), "") << name;
      const std::vector<double> pieces = cut::component_volumes(m);
      ASSERT_EQ(pieces.size(), 2u) << name;
      // The same pole at every level, within what decimating the boundary moves (the
      // coarsest level keeps few vertices on the pole).
      EXPECT_NEAR(pieces[0], cutter_pieces[0], 0.25 * cutter_pieces[0]) << name;
      if (name == "finest" || name == "focus at the cut")
      {
        EXPECT_NEAR(pieces[0], cutter_pieces[0], 0.05 * cutter_pieces[0]) << name;
      }
    }
  }
} // namespace lacerta
