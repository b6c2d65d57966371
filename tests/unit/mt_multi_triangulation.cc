// The Multi-Triangulation: builder, extraction, state transfer and storage invariants.

#include <lacerta/mt/builder.h>
#include <lacerta/mt/coarse_stiffness.h>
#include <lacerta/mt/homogenized_stiffness.h>
#include <lacerta/mt/lod.h>
#include <lacerta/mt/lod_query.h>
#include <lacerta/mt/storage.h>

#include <deal.II/base/function.h>

#include <gtest/gtest.h>

#include "mt_test_support.h"
#include "physics_test_support.h"
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <unistd.h>

namespace lacerta
{
  namespace
  {
    using mesh::Point3;
    using mesh::Tet;
    using test_support::make_query;

    std::set<Tet>
    sorted_tets(const std::vector<Tet> &tets)
    {
      std::set<Tet> result;
      for (Tet t : tets)
      {
        std::sort(t.begin(), t.end());
        result.insert(t);
      }
      return result;
    }

    std::set<Tet>
    active_set(const mt::MultiTriangulation &mt, const mt::Lod &lod)
    {
      std::vector<Tet> tets;
      for (const auto t : lod.active_tets())
        tets.push_back(mt.tets[t]);
      return sorted_tets(tets);
    }

    /// A unit box of 6^3 hexahedra split into tetrahedra (planar boundary).
    const mesh::TetMesh &
    box()
    {
      static const mesh::TetMesh mesh =
        test_support::distorted_box(6, 0.0, dealii::Point<3>(1, 1, 1));
      return mesh;
    }

    /// The box bent into a rounded shape: a curved boundary to approximate.
    mesh::TetMesh
    rounded_box()
    {
      std::vector<Point3> points = box().get_vertices();
      for (Point3 &p : points)
      {
        const Point3 c = {{p[0] - 0.5, p[1] - 0.5, p[2] - 0.5}};
        const double r = c[0] * c[0] + c[1] * c[1] + c[2] * c[2];
        for (unsigned int d = 0; d < 3; ++d)
          p[d] = c[d] * (1 - 0.3 * r);
      }
      return mesh::TetMesh(points, box().get_tets(), "rounded box");
    }

    /// The corners of a boundary face of @p m.
    std::array<Point3, 3>
    corners(const mesh::TetMesh &m, const mesh::BoundaryFace &face)
    {
      const Tet  &t = m.tet(face.tet);
      const auto &l = mesh::TetMesh::face_vertices[face.face];
      return {{m.vertex(t[l[0]]), m.vertex(t[l[1]]), m.vertex(t[l[2]])}};
    }

    const mt::MultiTriangulation &
    box_mt()
    {
      static const mt::MultiTriangulation mt =
        mt::build_multi_triangulation(box(), mt::BuilderParameters());
      return mt;
    }

    /// Boundary faces of an extracted mesh lie on the box's faces, which means no face
    /// inside the box is left unmatched: the mesh is conforming.
    void
    expect_conforming_box(const mesh::TetMesh &lod)
    {
      for (const auto &face : lod.get_boundary_faces())
      {
        const Tet &t      = lod.tet(face.tet);
        bool       planar = false;
        for (unsigned int d = 0; d < 3; ++d)
          for (const double side : {0.0, 1.0})
          {
            bool all = true;
            for (const unsigned int k : mesh::TetMesh::face_vertices[face.face])
              all = all && std::abs(lod.vertex(t[k])[d] - side) < 1e-12;
            planar = planar || all;
          }
        EXPECT_TRUE(planar)
          << "a boundary face inside the box: the mesh is not conforming";
      }
    }
  } // namespace


  TEST(MultiTriangulation, BuildIsConsistentAndDecimates)
  {
    const auto &mt = box_mt();
    EXPECT_NO_THROW(mt.check("box"));
    EXPECT_EQ(mt.n_vertices(), box().n_vertices());
    EXPECT_LT(mt.n_fine(0), box().n_tets() / 10);
    // Every vertex but those of the root comes back through exactly one node.
    std::set<unsigned int> inserted;
    for (unsigned int j = 1; j < mt.n_nodes(); ++j)
      EXPECT_TRUE(inserted.insert(mt.node_vertex[j]).second);
    // No collapse created a tetrahedron below the quality bound (none inverted).
    for (unsigned int t = 0; t < mt.n_tets(); ++t)
      if (mt.destroyer[t] != mesh::invalid_index)
      {
        const Tet &c = mt.tets[t];
        EXPECT_GE(mt::tet_quality(mt.vertices[c[0]],
                                  mt.vertices[c[1]],
                                  mt.vertices[c[2]],
                                  mt.vertices[c[3]]),
                  mt::BuilderParameters().minimum_quality);
      }
    // Errors never decrease towards the root.
    for (unsigned int t = 0; t < mt.n_tets(); ++t)
    {
      if (mt.destroyer[t] != mesh::invalid_index && mt.creator[t] != 0)
      {
        EXPECT_GE(mt.error[mt.creator[t]], mt.error[mt.destroyer[t]]);
      }
    }
  }


  TEST(MultiTriangulation, FinestIsTheInputAndCoarsestIsTheRoot)
  {
    const auto &mt = box_mt();
    mt::Lod     lod(mt);
    lod.extract(*make_query("uniform", {{"Cell size", "0"}}));
    EXPECT_EQ(active_set(mt, lod), sorted_tets(box().get_tets()));
    lod.extract(*make_query("uniform", {{"Cell size", "1000"}}));
    std::vector<Tet> root(mt.tets.begin() + mt.fine_begin[0],
                          mt.tets.begin() + mt.fine_begin[1]);
    EXPECT_EQ(active_set(mt, lod), sorted_tets(root));
  }


  TEST(MultiTriangulation, ExtractionsConformCoverTheVolumeAndKeepTheMass)
  {
    const auto                                  &mt = box_mt();
    const dealii::Functions::ConstantFunction<3> density(1000);
    for (const std::string size : {"0", "0.2", "0.4", "1000"})
    {
      mt::Lod lod(mt);
      auto query = make_query("focus", {{"Radius", "0.2"}, {"Cell size growth", size}});
      query->set_focus({{0.2, 0.3, 0.5}});
      lod.extract(*query);
      const mesh::TetMesh active = lod.make_mesh(lod.active_vertices(), "lod");
      // Every active tetrahedron satisfies the query: the node that would refine it
      // does not fail it.
      for (const auto t : lod.active_tets())
      {
        if (const auto d = mt.destroyer[t]; d != mesh::invalid_index)
        {
          const auto &b = mt.own_ball[d];
          EXPECT_LE(mt.own_error[d], query->minimum_error({{b[0], b[1], b[2]}}, b[3]));
        }
      }
      expect_conforming_box(active);
      EXPECT_NEAR(active.total_volume(), 1.0, 1e-12);
      const auto masses = physics::compute_masses(active, density);
      EXPECT_NEAR(std::accumulate(masses.begin(), masses.end(), 0.0), 1000.0, 1e-9);
    }
  }


  // The LOD is the smallest closed set that refines every fragment failing the query:
  // the nodes failing by their own error and ball, closed under parents, found here by
  // brute force over all nodes. The monotone bounds (error, ball) only cut the search.
  TEST(MultiTriangulation, LodIsTheClosureOfTheFailingNodes)
  {
    const auto  &mt       = box_mt();
    unsigned int n_closed = 0, n_bound = 0;
    for (const std::string growth : {"0.2", "0.5", "2"})
    {
      auto query = make_query("focus", {{"Radius", "0.1"}, {"Cell size growth", growth}});
      for (const Point3 &focus : {Point3{{0.1, 0.5, 0.5}}, Point3{{0.5, 0.5, 1.0}}})
      {
        query->set_focus(focus);
        mt::Lod lod(mt);
        lod.extract(*query);
        std::vector<char> in(mt.n_nodes(), 0), bound(mt.n_nodes(), 0);
        in[0] = bound[0] = 1;
        for (unsigned int j = 1; j < mt.n_nodes(); ++j)
        {
          const auto &o = mt.own_ball[j];
          in[j] = mt.own_error[j] > query->minimum_error({{o[0], o[1], o[2]}}, o[3]);
          const auto &b = mt.ball[j];
          bound[j]      = mt.error[j] > query->minimum_error({{b[0], b[1], b[2]}}, b[3]);
        }
        // Children have larger ids than their parents.
        for (unsigned int j = mt.n_nodes(); j-- > 1;)
          if (in[j])
            for (unsigned int k = mt.coarse_begin[j]; k < mt.coarse_begin[j + 1]; ++k)
              in[mt.creator[mt.coarse_list[k]]] = 1;
        for (unsigned int j = 0; j < mt.n_nodes(); ++j)
        {
          ASSERT_EQ(lod.is_applied(j), in[j] != 0) << "node " << j;
          // The bounds are conservative: every applied node passes them.
          EXPECT_TRUE(!in[j] || bound[j]) << "node " << j;
          n_closed += in[j];
          n_bound += bound[j];
        }
      }
    }
    // The own balls make a difference here (the bounds alone would apply more).
    EXPECT_LT(n_closed, n_bound);
  }


  TEST(MultiTriangulation, CurvedBoundaryStaysWithinTheHausdorffBound)
  {
    const mesh::TetMesh   input = rounded_box();
    mt::BuilderParameters parameters;
    parameters.maximum_boundary_error = 0.02;
    const auto mt                     = mt::build_multi_triangulation(input, parameters);
    EXPECT_NO_THROW(mt.check("rounded box"));
    {
      // Boundary decimation must not make the finest level unreachable.
      mt::Lod finest(mt);
      finest.extract(*make_query("uniform", {{"Cell size", "0"}}));
      EXPECT_EQ(active_set(mt, finest), sorted_tets(input.get_tets()));
    }
    mt::Lod    lod(mt);
    const auto root = lod.make_mesh(lod.active_vertices(), "root");
    // Hausdorff distance from the input boundary vertices to the root's boundary.
    const auto &points   = lod.active_vertices();
    double      diagonal = 0, hausdorff = 0;
    {
      Point3 low = input.vertex(0), high = low;
      for (const Point3 &p : input.get_vertices())
        for (unsigned int d = 0; d < 3; ++d)
        {
          low[d]  = std::min(low[d], p[d]);
          high[d] = std::max(high[d], p[d]);
        }
      diagonal = std::hypot(high[0] - low[0], high[1] - low[1], high[2] - low[2]);
    }
    for (unsigned int v = 0; v < input.n_vertices(); ++v)
    {
      if (!input.is_boundary_vertex(v))
        continue;
      double nearest = 1e300;
      for (const auto &face : root.get_boundary_faces())
      {
        // The distance to a dense sample of the triangle overestimates the distance to
        // the triangle by at most the sample spacing.
        const auto [a, b, c] = corners(root, face);
        for (int i = 0; i <= 20; ++i)
          for (int j = 0; i + j <= 20; ++j)
          {
            const double  s = i / 20.0, r = j / 20.0;
            const Point3  q = {{a[0] + s * (b[0] - a[0]) + r * (c[0] - a[0]),
                                a[1] + s * (b[1] - a[1]) + r * (c[1] - a[1]),
                                a[2] + s * (b[2] - a[2]) + r * (c[2] - a[2])}};
            const Point3 &p = input.vertex(v);
            nearest =
              std::min(nearest, std::hypot(p[0] - q[0], p[1] - q[1], p[2] - q[2]));
          }
      }
      hausdorff = std::max(hausdorff, nearest);
    }
    EXPECT_GT(hausdorff, 0.0);
    // Sampling adds at most the sample spacing to the exact distance.
    EXPECT_LE(hausdorff,
              parameters.maximum_boundary_error * diagonal
                + root.edge_length_range()[1] / 20);
    EXPECT_LT(points.size(), input.n_vertices());
    // The volume between the two boundaries is at most their area times the distance.
    double area = 0;
    for (const auto &face : input.get_boundary_faces())
    {
      const auto [a, b, c] = corners(input, face);
      const Point3 u       = {{b[0] - a[0], b[1] - a[1], b[2] - a[2]}};
      const Point3 w       = {{c[0] - a[0], c[1] - a[1], c[2] - a[2]}};
      area += 0.5
              * std::hypot(u[1] * w[2] - u[2] * w[1],
                           u[2] * w[0] - u[0] * w[2],
                           u[0] * w[1] - u[1] * w[0]);
    }
    EXPECT_LE(std::abs(root.total_volume() - input.total_volume()), area * hausdorff);
    std::cout << "rounded box: root " << root.n_tets()
              << " tetrahedra, Hausdorff distance " << hausdorff << " ("
              << hausdorff / diagonal << " of the diagonal), volume "
              << root.total_volume() / input.total_volume() << " of the input\n";
  }


  TEST(MultiTriangulation, IncrementalExtractionEqualsExtractionFromScratch)
  {
    const auto &mt = box_mt();
    auto query = make_query("focus", {{"Radius", "0.15"}, {"Cell size growth", "0.3"}});
    mt::Lod incremental(mt);
    bool    some_change = false;
    for (int step = 0; step <= 20; ++step)
    {
      query->set_focus({{0.05 * step, 0.5 + 0.3 * std::sin(step), 0.5}});
      some_change |= incremental.extract(*query);
      mt::Lod scratch(mt);
      scratch.extract(*query);
      ASSERT_EQ(active_set(mt, incremental), active_set(mt, scratch)) << "step " << step;
      for (unsigned int j = 0; j < mt.n_nodes(); ++j)
        ASSERT_EQ(incremental.is_applied(j), scratch.is_applied(j));
    }
    EXPECT_TRUE(some_change);
  }


  // Small steps exercise the skipping of frontier nodes whose slack the focus has not
  // travelled yet; a nonzero cell size near the focus makes some nodes never needed.
  TEST(MultiTriangulation, IncrementalExtractionWithSmallStepsEqualsExtractionFromScratch)
  {
    const auto &mt = box_mt();
    for (const std::string near : {"0", "0.1"})
    {
      auto    query = make_query("focus",
                              {{"Radius", "0.1"},
                                  {"Cell size growth", "0.5"},
                                  {"Cell size near the focus", near}});
      mt::Lod incremental(mt);
      for (int step = 0; step <= 150; ++step)
      {
        query->set_focus({{0.007 * step, 0.5 + 0.2 * std::sin(0.05 * step), 0.4}});
        incremental.extract(*query);
        mt::Lod scratch(mt);
        scratch.extract(*query);
        for (unsigned int j = 0; j < mt.n_nodes(); ++j)
          ASSERT_EQ(incremental.is_applied(j), scratch.is_applied(j))
            << "node " << j << ", step " << step << ", near size " << near;
      }
      // Another query object: everything is tested again.
      const auto uniform = make_query("uniform", {{"Cell size", "0.3"}});
      incremental.extract(*uniform);
      mt::Lod scratch(mt);
      scratch.extract(*uniform);
      ASSERT_EQ(active_set(mt, incremental), active_set(mt, scratch));
    }
  }


  // A deeper MT (jittered 10^3 box) along a curved path of many small moves: the
  // answers memoised with the travel they hold to are reused across extractions, and
  // the result must stay that of an extraction from scratch.
  TEST(MultiTriangulation, MemoisedAnswersKeepIncrementalEqualToScratchOnADeeperMt)
  {
    const mesh::TetMesh input = test_support::distorted_box(10, 0.2, {1, 1, 1});
    const auto          mt    = mt::build_multi_triangulation(input, {});
    for (const std::string growth : {"0.2", "0.5"})
    {
      auto         query = make_query("focus",
                              {{"Radius", "0.1"},
                                       {"Cell size growth", growth},
                                       {"Cell size near the focus", "0.05"}});
      mt::Lod      incremental(mt);
      unsigned int n_changes = 0;
      for (int k = 0; k < 200; ++k)
      {
        query->set_focus({{0.1 + 0.004 * k,
                           0.5 + 0.2 * std::sin(0.03 * k),
                           0.5 + 0.1 * std::cos(0.05 * k)}});
        n_changes += incremental.extract(*query);
        if (k % 5 != 0)
          continue;
        mt::Lod scratch(mt);
        scratch.extract(*query);
        for (unsigned int j = 0; j < mt.n_nodes(); ++j)
          ASSERT_EQ(incremental.is_applied(j), scratch.is_applied(j))
            << "node " << j << ", move " << k << ", growth " << growth;
      }
      EXPECT_GT(n_changes, 100u);
    }
  }


  // The slack of the focus query is a true lower bound: a focus that moves less than it
  // leaves the answer of the query for that ball and error unchanged.
  TEST(MultiTriangulation, FocusSlackIsALowerBound)
  {
    auto query = make_query("focus", {{"Radius", "0.1"}, {"Cell size growth", "0.5"}});
    unsigned int seed    = 12345;
    const auto   uniform = [&seed]()
    {
      seed = seed * 1103515245u + 12345u;
      return (seed >> 8) / double(1u << 24);
    };
    unsigned int n_finite = 0;
    for (int trial = 0; trial < 2000; ++trial)
    {
      const Point3 focus  = {{uniform(), uniform(), uniform()}};
      const Point3 center = {{uniform(), uniform(), uniform()}};
      const double radius = 0.2 * uniform();
      const double error  = mt::LodQuery::error_of_cell_size(0.3 * uniform());
      query->set_focus(focus);
      const bool   before = query->minimum_error(center, radius) < error;
      const double slack  = query->focus_slack(center, radius, error);
      ASSERT_GE(slack, 0);
      if (!std::isfinite(slack))
        continue;
      ++n_finite;
      // Move by just under the slack in a random direction and towards the center.
      for (int k = 0; k < 2; ++k)
      {
        Point3 direction =
          k == 0
            ? Point3{{uniform() - 0.5, uniform() - 0.5, uniform() - 0.5}}
            : Point3{{center[0] - focus[0], center[1] - focus[1], center[2] - focus[2]}};
        const double length = std::hypot(direction[0], direction[1], direction[2]);
        if (length == 0)
          continue;
        Point3 moved = focus;
        for (unsigned int d = 0; d < 3; ++d)
          moved[d] += 0.999 * slack * direction[d] / length;
        query->set_focus(moved);
        EXPECT_EQ(query->minimum_error(center, radius) < error, before)
          << "trial " << trial;
      }
    }
    EXPECT_GT(n_finite, 1000u);
  }


  TEST(MultiTriangulation, NewParticlesLieInTetrahedraOfThePreviousLevel)
  {
    const auto &mt = box_mt();
    auto    query = make_query("focus", {{"Radius", "0.1"}, {"Cell size growth", "0.5"}});
    mt::Lod lod(mt);
    unsigned int located = 0;
    for (int step = 0; step <= 10; ++step)
    {
      const std::vector<std::uint32_t> before(lod.active_tets().begin(),
                                              lod.active_tets().end());
      const std::set<std::uint32_t>    previous(before.begin(), before.end());
      const auto                       old_vertices = lod.active_vertices();
      query->set_focus({{0.1 * step, 0.5, 0.5}});
      lod.extract(*query);
      for (const auto v : lod.active_vertices())
      {
        if (std::binary_search(old_vertices.begin(), old_vertices.end(), v))
          continue;
        const auto [tet, lambda] = lod.locate_in_previous(v);
        EXPECT_TRUE(previous.count(tet)) << "vertex " << v;
        for (const double l : lambda)
          EXPECT_GE(l, -1e-10) << "vertex " << v << " outside its tetrahedron";
        EXPECT_NEAR(lambda[0] + lambda[1] + lambda[2] + lambda[3], 1.0, 1e-12);
        ++located;
      }
    }
    EXPECT_GT(located, 10u);
  }


  TEST(MultiTriangulation, CacheLoadsIdenticallyAndRebuildsBadFiles)
  {
    const std::string directory = "mt_cache_test";
    std::filesystem::remove_all(directory);
    mt::CacheReport report;
    const auto      built = mt::load_or_build(box(), {}, {}, directory, report);
    EXPECT_FALSE(report.loaded);
    EXPECT_EQ(report.reason, "missing");
    const auto loaded = mt::load_or_build(box(), {}, {}, directory, report);
    EXPECT_TRUE(report.loaded);
    EXPECT_EQ(loaded.tets, built.tets);
    EXPECT_EQ(loaded.coarse_list, built.coarse_list);
    EXPECT_EQ(loaded.error, built.error);
    EXPECT_EQ(loaded.ball, built.ball);
    EXPECT_EQ(loaded.vertex_node, built.vertex_node);
    const std::string file = report.file;

    // One flipped byte in the middle: detected, rebuilt and rewritten.
    {
      std::fstream f(file, std::ios::in | std::ios::out | std::ios::binary);
      f.seekg(static_cast<std::streamoff>(std::filesystem::file_size(file) / 2));
      char c = 0;
      f.read(&c, 1);
      f.seekp(static_cast<std::streamoff>(std::filesystem::file_size(file) / 2));
      c = static_cast<char>(~c);
      f.write(&c, 1);
    }
    const auto repaired = mt::load_or_build(box(), {}, {}, directory, report);
    EXPECT_FALSE(report.loaded);
    EXPECT_NE(report.reason.find("corrupted"), std::string::npos) << report.reason;
    EXPECT_EQ(repaired.tets, built.tets);
    mt::load_or_build(box(), {}, {}, directory, report);
    EXPECT_TRUE(report.loaded);

    // Truncated: detected.
    std::filesystem::resize_file(file, std::filesystem::file_size(file) - 10);
    std::string reason;
    EXPECT_FALSE(mt::load(file, mt::cache_key(box(), {}, {}), reason));
    EXPECT_NE(reason.find("corrupted"), std::string::npos) << reason;

    // Stale: a file made for other builder parameters under this name.
    mt::BuilderParameters other;
    other.minimum_quality = 0.2;
    mt::save(built, mt::cache_key(box(), other, {}), file);
    mt::load_or_build(box(), {}, {}, directory, report);
    EXPECT_FALSE(report.loaded);
    EXPECT_NE(report.reason.find("stale"), std::string::npos) << report.reason;
    std::filesystem::remove_all(directory);
  }


  TEST(MultiTriangulation, LockedVerticesStayInEveryLevel)
  {
    const std::vector<unsigned int> locked = {0, 5, 17, 100};
    const auto                      mt = mt::build_multi_triangulation(box(), {}, locked);
    for (const unsigned int v : locked)
      EXPECT_EQ(mt.vertex_node[v], 0u);
  }
} // namespace lacerta


namespace lacerta
{
  TEST(MultiTriangulation, CondensedStiffnessKeepsTheInputCellsAndIsNonNegative)
  {
    const auto &mt   = box_mt();
    const auto  rule = [](const std::array<mesh::Point3, 4> &x)
    { return physics::paper_edge_stiffnesses(x, 1e4); };
    const auto k = mt::condensed_edge_stiffnesses(mt, rule);
    ASSERT_EQ(k.size(), mt.n_tets());
    double total_input = 0, total_root = 0;
    for (unsigned int t = 0; t < mt.n_tets(); ++t)
    {
      std::array<mesh::Point3, 4> x;
      for (unsigned int i = 0; i < 4; ++i)
        x[i] = mt.vertices[mt.tets[t][i]];
      const auto expected = rule(x);
      for (unsigned int e = 0; e < 6; ++e)
      {
        ASSERT_TRUE(std::isfinite(k[t][e])) << "tet " << t;
        EXPECT_GE(k[t][e], 0.0) << "tet " << t;
        if (mt.destroyer[t] == mesh::invalid_index)
        {
          EXPECT_EQ(k[t][e], expected[e]) << "input tet " << t;
          total_input += k[t][e];
        }
        if (mt.creator[t] == 0)
          total_root += k[t][e];
      }
    }
    // The root carries stiffness: nothing was condensed to nothing.
    EXPECT_GT(total_root, 0.0);
    EXPECT_GT(total_input, 0.0);
  }
} // namespace lacerta


namespace lacerta
{
  TEST(MultiTriangulation, HomogenizedScaleMatchesTheInputMeshsEnergyUnderUniformStrain)
  {
    // Under a uniform strain every tetrahedron's Section 3.2 springs hold 3 E per
    // volume summed over the six unit strains (Σ over an orthonormal basis of
    // (n·ε n)² is |n ⊗ n|² = 1 per edge): the energy of the affine field. Relaxing the
    // interior can only lower it.
    const double E    = 1e4;
    const auto   rule = [&](const std::array<mesh::Point3, 4> &x)
    { return physics::paper_edge_stiffnesses(x, E); };
    // The regular box's lattice relaxes nothing, and its root (no interior vertex)
    // cannot: the scale is 1.
    const mt::HomogenizedScale box = mt::homogenized_coarse_scale(box_mt(), rule);
    EXPECT_NEAR(box.fine_energy_density, 3 * E, 1e-8 * E);
    EXPECT_NEAR(box.coarse_energy_density, 3 * E, 1e-8 * E);
    EXPECT_NEAR(box.scale, 1.0, 1e-8);
    // A distorted box relaxes; its root of a few cells does not, so the coarse cells
    // are the stiffer material and are scaled down.
    const mt::MultiTriangulation distorted = mt::build_multi_triangulation(
      test_support::distorted_box(8, 0.4, dealii::Point<3>(1, 1, 1)),
      mt::BuilderParameters());
    const mt::HomogenizedScale down = mt::homogenized_coarse_scale(distorted, rule);
    EXPECT_LT(down.fine_energy_density, 0.9 * 3 * E);
    EXPECT_LT(down.scale, 0.9);
    // The rounded box's root keeps interior vertices and relaxes more than the input
    // mesh: scaled up. All its cells are decimated ones, so the energy is linear in
    // the scale and the scale is the ratio of the densities.
    const mt::MultiTriangulation rounded =
      mt::build_multi_triangulation(rounded_box(), mt::BuilderParameters());
    for (std::uint32_t t = rounded.fine_begin[0]; t < rounded.fine_begin[1]; ++t)
      ASSERT_NE(rounded.destroyer[t], mesh::invalid_index);
    const mt::HomogenizedScale h = mt::homogenized_coarse_scale(rounded, rule);
    EXPECT_LT(h.fine_energy_density, 3 * E);
    EXPECT_LT(h.coarse_energy_density, h.fine_energy_density);
    EXPECT_GT(h.scale, 1.02);
    EXPECT_NEAR(h.scale, h.fine_energy_density / h.coarse_energy_density, 1e-5);
    // It does not depend on the modulus.
    const mt::HomogenizedScale stiffer =
      mt::homogenized_coarse_scale(rounded,
                                   [&](const std::array<mesh::Point3, 4> &x)
                                   { return physics::paper_edge_stiffnesses(x, 7 * E); });
    EXPECT_NEAR(stiffer.scale, h.scale, 1e-5 * h.scale);
    EXPECT_NEAR(stiffer.fine_energy_density, 7 * h.fine_energy_density, 1e-6 * E);

    // Kept in a file: read back for the same rule only, recomputed when the file is
    // damaged.
    const std::string file = (std::filesystem::temp_directory_path()
                              / ("lacerta_homogenized_" + std::to_string(::getpid())))
                               .string();
    std::filesystem::remove(file);
    const mt::HomogenizedScale first =
      mt::cached_homogenized_coarse_scale(rounded, rule, file);
    EXPECT_FALSE(first.loaded);
    EXPECT_EQ(first.scale, h.scale);
    const mt::HomogenizedScale again =
      mt::cached_homogenized_coarse_scale(rounded, rule, file);
    EXPECT_TRUE(again.loaded);
    EXPECT_EQ(again.scale, h.scale);
    EXPECT_EQ(again.fine_energy_density, h.fine_energy_density);
    const mt::HomogenizedScale other = mt::cached_homogenized_coarse_scale(
      rounded,
      [&](const std::array<mesh::Point3, 4> &x)
      { return physics::paper_edge_stiffnesses(x, 7 * E); },
      file);
    EXPECT_FALSE(other.loaded);
    std::ofstream(file) << "lacerta-homogenized-scale-1 12 nan";
    EXPECT_FALSE(mt::cached_homogenized_coarse_scale(rounded, rule, file).loaded);
    EXPECT_TRUE(mt::cached_homogenized_coarse_scale(rounded, rule, file).loaded);
    std::filesystem::remove(file);
  }
} // namespace lacerta
