// Two stages of a sweep on their own: the cells it changes (cut/cell_selection.h),
// and their children (cut/child_builder.h): one particle per cut edge shared by the
// cells around it, states interpolated in the parent, faces on the cut flagged, and
// the points on the cut copied once per side.
#include <lacerta/cut/cell_selection.h>
#include <lacerta/cut/child_builder.h>
#include <lacerta/cut/crossing_decisions.h>
#include <lacerta/mesh/tet_mesh.h>
#include <lacerta/physics/particle_system.h>

#include <gtest/gtest.h>

#include "physics_test_support.h"
#include <algorithm>
#include <map>
#include <memory>

namespace
{
  using namespace lacerta;
  using cut::Point;

  /// Two tetrahedra glued along the face {0, 2, 3}: {0, e_x, e_y, e_z} and
  /// {0, -e_x, e_z, e_y}, deformed by doubling every coordinate.
  struct TwoTets
  {
    mesh::TetMesh                            mesh;
    std::unique_ptr<physics::ParticleSystem> system;

    TwoTets()
    {
      const std::vector<mesh::Point3> x = {
        {{0, 0, 0}}, {{1, 0, 0}}, {{0, 1, 0}}, {{0, 0, 1}}, {{-1, 0, 0}}};
      const std::vector<mesh::Tet> t = {{{0, 1, 2, 3}}, {{0, 4, 3, 2}}};
      mesh                           = mesh::TetMesh(x, t, "two tets");
      mesh.enable_local_updates();
      system = test_support::make_system(mesh, 1000.0, 1e4);
      for (double &c : system->position)
        c *= 2;
    }
  };

  /// The plane y = @p y swept by a blade along x from @p x0 to @p x1 (z from 4 down
  /// to -2), in deformed coordinates.
  cut::SweptTriangles
  sweep_in_plane_y(const double y, const double x0 = -3, const double x1 = 3)
  {
    const Point from_tail{{x0, y, 4}}, from_head{{x0, y, -2}};
    const Point to_tail{{x1, y, 4}}, to_head{{x1, y, -2}};
    return {{{{from_tail, from_head, to_tail}}, {{to_tail, from_head, to_head}}}};
  }
} // namespace


TEST(CutChildBuilder, CellsCutThroughShareTheirEdgesPointsAndCopyThemOncePerSide)
{
  TwoTets                tets;
  cut::CrossingDecisions decisions(tets.mesh, *tets.system, 0.05);
  // y = 0.5 at rest (1 deformed) separates vertex 2 in both cells.
  decisions.record_sweep({0, 1}, sweep_in_plane_y(1.0));
  std::vector<cut::TetCut>      cuts;
  std::vector<cut::SplitResult> results(2);
  for (unsigned int t = 0; t < 2; ++t)
  {
    const auto d = decisions.decide_cell(t);
    ASSERT_TRUE(d.complete);
    cut::TetCut c = decisions.whole_cell(t);
    c.vertex_side = d.side;
    c.cut_edges   = d.crossed;
    for (unsigned int e = 0; e < 6; ++e)
      c.edge_parameter[e] = d.t[e];
    cuts.push_back(c);
    cut::split_tetrahedron(c, results[t], 0.05);
  }

  cut::ChildBuilder      builder(tets.mesh, *tets.system);
  cut::CutStepStatistics statistics;
  builder.build({0, 1}, cuts, results, {}, decisions, statistics, nullptr);

  // Four cut edges (0-2 and 2-3 shared by the two cells, 1-2 and 4-2 not): four new
  // points, each copied once where the crack opens between the two sides.
  EXPECT_EQ(statistics.cut_tets, 2u);
  EXPECT_EQ(statistics.created_tets, results[0].n_children + results[1].n_children);
  EXPECT_EQ(builder.children().size(), statistics.created_tets);
  EXPECT_EQ(statistics.new_particles, 8u);
  EXPECT_EQ(statistics.copied_particles.size(), 4u);
  EXPECT_EQ(tets.system->n_particles(), 13u);
  EXPECT_EQ(tets.mesh.n_vertices(), 13u);

  // Every new point lies at the middle of its edge at rest, and its particle at the
  // middle of the deformed edge (the parent's affine map); a copy shares both.
  for (unsigned int v = 5; v < 13; ++v)
  {
    EXPECT_NEAR(tets.mesh.vertex(v)[1], 0.5, 1e-12) << v;
    for (unsigned int d = 0; d < 3; ++d)
      EXPECT_NEAR(tets.system->position[3 * v + d], 2 * tets.mesh.vertex(v)[d], 1e-12);
  }

  // Each side gets its own copies: no child holds a point of the other side. The
  // children with vertex 2 use one copy of each point, the others the other copy.
  std::map<unsigned int, int> side_of_point;
  for (const auto &child : builder.children())
  {
    const bool tip = std::count(child.begin(), child.end(), 2u) == 1;
    for (const unsigned int v : child)
      if (v >= 5)
      {
        const auto [it, inserted] = side_of_point.emplace(v, tip);
        EXPECT_EQ(it->second, tip) << "point " << v << " on both sides";
      }
  }
  EXPECT_EQ(side_of_point.size(), 8u);

  // The faces on the cut are flagged on both sides, two per cell (one per side).
  unsigned int cut_faces = 0;
  for (const auto &ids : builder.face_ids())
    cut_faces += std::count(ids.begin(), ids.end(), cut::cut_boundary_id);
  EXPECT_EQ(cut_faces, 4u);
  // New points and copies are on the cut of the stroke.
  for (unsigned int v = 5; v < 13; ++v)
    EXPECT_TRUE(decisions.on_cut(v));
}


TEST(CutCellSelection, ACellCutThroughSplitsItsNeighboursThroughTheSharedCutPoints)
{
  TwoTets                tets;
  cut::CrossingDecisions decisions(tets.mesh, *tets.system, 0.05);
  // The blade comes from x > 0 and stops just past the shared face x = 0: it cuts the
  // first cell through (edges 0-2, 1-2, 2-3) but not the second (its edge 4-2 is
  // crossed at x = -1, deformed).
  decisions.record_sweep({0, 1}, sweep_in_plane_y(1.0, 3, -0.01));
  ASSERT_TRUE(decisions.decide_cell(0).complete);
  ASSERT_FALSE(decisions.decide_cell(1).complete);

  cut::CellSelection selection(tets.mesh);
  selection.select(decisions);
  // Both cells change: the first is cut through, the second refined through the two
  // cut points it shares with it (the mesh stays conforming), without separating.
  ASSERT_EQ(selection.removed().size(), 2u);
  EXPECT_TRUE(selection.separated().empty());
  for (std::size_t k = 0; k < 2; ++k)
  {
    const cut::TetCut &c         = selection.cuts()[k];
    const bool         cell      = selection.removed()[k];
    unsigned int       cut_edges = 0;
    for (unsigned int e = 0; e < 6; ++e)
      cut_edges += (c.cut_edges >> e) & 1u;
    EXPECT_EQ(cut_edges, cell == 0 ? 3u : 2u);
    const auto sides =
      std::count(c.vertex_side.begin(), c.vertex_side.end(), c.vertex_side[0]);
    EXPECT_EQ(sides, cell == 0 ? 3 : 4) << "cell " << cell;
  }
  using Key = cut::CrossingDecisions;
  EXPECT_TRUE(decisions.is_applied(Key::edge_key(0, 2)));
  EXPECT_TRUE(decisions.is_applied(Key::edge_key(1, 2)));
  EXPECT_TRUE(decisions.is_applied(Key::edge_key(2, 3)));
}
