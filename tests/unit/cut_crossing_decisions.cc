// The scalpel's decision rules one by one (cut/crossing_decisions.h), on a single
// tetrahedron or a pair: where an edge is crossed, on which side its ends lie, when a
// vertex snaps onto the cut, when a cell is cut through, and what a stroke forgets.
#include <lacerta/cut/crossing_decisions.h>
#include <lacerta/mesh/point.h>
#include <lacerta/mesh/tet_mesh.h>
#include <lacerta/physics/particle_system.h>

#include <gtest/gtest.h>

#include "physics_test_support.h"
#include <cmath>
#include <memory>

namespace
{
  using namespace lacerta;
  using cut::CrossingDecisions;
  using cut::Point;
  using cut::SweptTriangles;

  /// The sweep of a blade from z = 2 down to z = -1, in the plane x = @p x, moved
  /// from y = @p y0 to y = @p y1 (swept triangles as the cutter builds them).
  SweptTriangles
  sweep_in_plane_x(const double x, const double y0, const double y1)
  {
    const Point from_tail{{x, y0, 2}}, from_head{{x, y0, -1}};
    const Point to_tail{{x, y1, 2}}, to_head{{x, y1, -1}};
    return {{{{from_tail, from_head, to_tail}}, {{to_tail, from_head, to_head}}}};
  }

  /// The unit normal of a sweep, as record_sweep() takes it.
  Point
  normal_of(const SweptTriangles &s)
  {
    return mesh::normalized(
      mesh::cross(mesh::sub(s[0][1], s[0][0]), mesh::sub(s[0][2], s[0][0])));
  }

  /// The corner tetrahedron {0, e_x, e_y, e_z} (vertex 0 at the origin, 1 on the x
  /// axis), optionally with a second one glued to its face x = 0, with its particles.
  struct Tets
  {
    mesh::TetMesh                            mesh;
    std::unique_ptr<physics::ParticleSystem> system;
    std::unique_ptr<CrossingDecisions>       decisions;

    explicit Tets(const bool two = false)
    {
      std::vector<mesh::Point3> x = {{{0, 0, 0}}, {{1, 0, 0}}, {{0, 1, 0}}, {{0, 0, 1}}};
      std::vector<mesh::Tet>    t = {{{0, 1, 2, 3}}};
      if (two)
      {
        x.push_back({{-1, 0, 0}});
        t.push_back({{0, 4, 3, 2}});
      }
      mesh = mesh::TetMesh(x, t, "tets");
      mesh.enable_local_updates();
      system    = test_support::make_system(mesh, 1000.0, 1e4);
      decisions = std::make_unique<CrossingDecisions>(mesh, *system, 0.05);
    }

    std::vector<unsigned int>
    all_cells() const
    {
      std::vector<unsigned int> cells(mesh.n_tets());
      for (unsigned int t = 0; t < cells.size(); ++t)
        cells[t] = t;
      return cells;
    }
  };
} // namespace


TEST(CutCrossingDecisions, AnEdgeIsCrossedWhereThePlaneMeetsItWithItsEndsSides)
{
  Tets                  tets;
  const SweptTriangles  s = sweep_in_plane_x(0.25, -1, 2);
  std::array<double, 2> distance{};
  const auto c = tets.decisions->edge_crossing(0, 1, s, normal_of(s), distance);
  EXPECT_NEAR(c.t, 0.25, 1e-15);
  // Vertex 0 (x = 0) lies on the side opposite to the normal's.
  EXPECT_EQ(c.side, normal_of(s)[0] > 0 ? -1 : 1);
  EXPECT_NEAR(distance[0], 0.25, 1e-15);
  EXPECT_NEAR(distance[1], 0.75, 1e-15);
  // An edge in the plane x = 0 does not cross x = 0.25.
  EXPECT_EQ(tets.decisions->edge_crossing(2, 3, s, normal_of(s), distance).side, 0);
}


TEST(CutCrossingDecisions, AVertexOnTheBladesPlaneIsOnItsPositiveSide)
{
  Tets                  tets;
  const SweptTriangles  s = sweep_in_plane_x(0, -1, 2);
  const Point           n = normal_of(s);
  std::array<double, 2> distance{};
  // Vertex 0 lies exactly on the plane x = 0: it counts as on the positive side, so
  // the edge to vertex 1 is crossed (at 0) only if vertex 1 lies on the negative side.
  const auto c = tets.decisions->edge_crossing(0, 1, s, n, distance);
  if (n[0] < 0)
  {
    EXPECT_EQ(c.side, 1);
    EXPECT_EQ(c.t, 0.0);
  }
  else
    EXPECT_EQ(c.side, 0);
}


TEST(CutCrossingDecisions, APlaneThroughACellCutsItThroughWithConsistentSides)
{
  Tets tets;
  tets.decisions->record_sweep(tets.all_cells(), sweep_in_plane_x(0.5, -1, 2));
  // x = 0.5 crosses the three edges at vertex 1, at their middles.
  EXPECT_EQ(tets.decisions->new_crossings().size(), 3u);
  EXPECT_TRUE(tets.decisions->new_on_cut().empty());
  const auto d = tets.decisions->decide_cell(0);
  EXPECT_TRUE(d.complete);
  for (unsigned int k = 0; k < 4; ++k)
    if (k != 1)
    {
      EXPECT_EQ(d.side[k], d.side[0]);
      EXPECT_NE(d.side[k], 0);
    }
  EXPECT_EQ(d.side[1], -d.side[0]);
  for (unsigned int e = 0; e < 6; ++e)
    if ((d.crossed >> e) & 1u)
      EXPECT_NEAR(d.t[e], 0.5, 1e-15);
}


TEST(CutCrossingDecisions, ASurfaceThatEndsInsideACellDoesNotCutItThrough)
{
  Tets tets;
  // The blade stops at y = 0.1: it crosses edges 0-1 and 1-3 (both at y = 0), not
  // edge 1-2 (crossed at y = 0.5).
  tets.decisions->record_sweep(tets.all_cells(), sweep_in_plane_x(0.5, -1, 0.1));
  EXPECT_EQ(tets.decisions->new_crossings().size(), 2u);
  const auto d = tets.decisions->decide_cell(0);
  EXPECT_NE(d.crossed, 0);
  EXPECT_FALSE(d.complete);
  // The next sweep finishes it: the two recorded crossings stand, a third is added.
  tets.decisions->record_sweep(tets.all_cells(), sweep_in_plane_x(0.5, 0.1, 2));
  EXPECT_EQ(tets.decisions->new_crossings().size(), 1u);
  EXPECT_TRUE(tets.decisions->decide_cell(0).complete);
}


TEST(CutCrossingDecisions, AVertexNearThePlaneSnapsOntoTheCutAndItsEdgesAreNotCut)
{
  Tets tets;
  // x = 0.02: vertices 0, 2 and 3 lie 0.02 from the plane, within 0.05 of the cell's
  // longest edge (sqrt 2); the edges from vertex 1 are not cut, the three go on the
  // cut. The fourth would be refused (the cell would lie in the crack), but vertex 1
  // is 0.98 away.
  tets.decisions->record_sweep(tets.all_cells(), sweep_in_plane_x(0.02, -1, 2));
  EXPECT_TRUE(tets.decisions->new_crossings().empty());
  EXPECT_TRUE(tets.decisions->on_cut(0));
  EXPECT_TRUE(tets.decisions->on_cut(2));
  EXPECT_TRUE(tets.decisions->on_cut(3));
  EXPECT_FALSE(tets.decisions->on_cut(1));
  EXPECT_FALSE(tets.decisions->may_snap(1));
  EXPECT_EQ(tets.decisions->decide_cell(0).crossed, 0);
  // The cell is left whole with its face on the cut flagged: vertices 0, 2, 3 at 0.
  const auto whole = tets.decisions->whole_cell(0);
  EXPECT_EQ(whole.vertex_side[0], 0);
  EXPECT_NE(whole.vertex_side[1], 0);
  EXPECT_EQ(whole.vertex_side[2], 0);
  EXPECT_EQ(whole.vertex_side[3], 0);
}


TEST(CutCrossingDecisions, AVertexWithADecidedCrossingDoesNotSnapLater)
{
  Tets tets(true);
  tets.decisions->record_sweep(tets.all_cells(), sweep_in_plane_x(0.5, -1, 2));
  ASSERT_FALSE(tets.decisions->new_crossings().empty());
  // Vertex 1 has crossings on its edges: it lies off the cut for the stroke.
  EXPECT_FALSE(tets.decisions->may_snap(1));
  // Vertex 4, on the other cell, has none.
  EXPECT_TRUE(tets.decisions->may_snap(4));
}


TEST(CutCrossingDecisions, AnEdgeCrossedInAndOutAgainIsNotCrossed)
{
  Tets                 tets;
  const SweptTriangles there = sweep_in_plane_x(0.3, -1, 2);
  tets.decisions->record_sweep(tets.all_cells(), there);
  ASSERT_EQ(tets.decisions->new_crossings().size(), 3u);
  // The blade comes back the other way at x = 0.7: the edges went into the surface
  // and out again, so their ends lie on one side, and the crossings are forgotten.
  const SweptTriangles back = sweep_in_plane_x(0.7, 2, -1);
  tets.decisions->record_sweep(tets.all_cells(), back);
  EXPECT_EQ(tets.decisions->new_crossings().size(), 3u);
  EXPECT_EQ(tets.decisions->decide_cell(0).crossed, 0);
}


TEST(CutCrossingDecisions, TheSameCrossingSeenAgainKeepsItsFirstDecision)
{
  Tets tets;
  tets.decisions->record_sweep(tets.all_cells(), sweep_in_plane_x(0.5, -1, 2));
  const auto first = tets.decisions->decide_cell(0);
  // The tissue moves vertex 1 across the plane; the next sweep of the same part
  // judges it on its recorded side and decides nothing new.
  tets.system->position[3 * 1] = 0.4;
  const SweptTriangles again   = sweep_in_plane_x(0.5, -1, 2);
  tets.decisions->record_sweep(tets.all_cells(), again);
  EXPECT_TRUE(tets.decisions->new_crossings().empty());
  EXPECT_EQ(tets.decisions->kept_side(1, normal_of(again)), first.side[1]);
  const auto second = tets.decisions->decide_cell(0);
  EXPECT_EQ(second.crossed, first.crossed);
  EXPECT_EQ(second.side, first.side);
  EXPECT_EQ(second.t, first.t);
}


TEST(CutCrossingDecisions, AppliedCrossingsGoAndTheStrokesEndForgetsTheRest)
{
  Tets tets;
  tets.decisions->record_sweep(tets.all_cells(), sweep_in_plane_x(0.5, -1, 2));
  const auto key = CrossingDecisions::edge_key(0, 1);
  EXPECT_TRUE(tets.decisions->apply_crossing(key));
  EXPECT_FALSE(tets.decisions->apply_crossing(key));
  EXPECT_TRUE(tets.decisions->is_applied(key));
  tets.decisions->forget_applied();
  // Edges 1-2 and 1-3 keep their crossings; 0-1 is gone, so the cell is no longer
  // consistently cut.
  EXPECT_FALSE(tets.decisions->decide_cell(0).complete);
  tets.decisions->mark_on_cut(2);
  tets.decisions->end_stroke();
  EXPECT_EQ(tets.decisions->decide_cell(0).crossed, 0);
  EXPECT_FALSE(tets.decisions->on_cut(2));
}


TEST(CutCrossingDecisions, TheSnappingScaleIsTheLongestEdgeOfTheCellsAroundTheEdge)
{
  Tets tets(true);
  // Edge 0-1 (length 1) lies in the first cell only, whose longest edge is sqrt 2;
  // edge 0-2 is shared by both cells, whose longest edges are sqrt 2 too.
  EXPECT_NEAR(tets.decisions->cell_size_around(0, 1), std::sqrt(2.0), 1e-15);
  EXPECT_NEAR(tets.decisions->cell_size_around(0, 2), std::sqrt(2.0), 1e-15);
}


TEST(CutCrossingDecisions, APartReachesAheadOfTheSweepAndNearItsEarlierSweepsOnly)
{
  Tets tets;
  // The part of the surface in the plane x = 0.1, swept along +y: first from y = -1
  // to 0.5, then (the sweep being judged) from 0.5 to 0.8.
  tets.decisions->record_sweep(tets.all_cells(), sweep_in_plane_x(0.1, -1, 0.5));
  const SweptTriangles current = sweep_in_plane_x(0.1, 0.5, 0.8);
  // Vertex 2 (y = 1) lies ahead of the sweep's start.
  EXPECT_TRUE(tets.decisions->part_reaches(2, 0.01, current));
  // Vertex 0 (y = 0) lies behind it, 0.51 from its triangles but 0.1 from the part's
  // earlier sweep.
  EXPECT_TRUE(tets.decisions->part_reaches(0, 0.2, current));
  EXPECT_FALSE(tets.decisions->part_reaches(0, 0.05, current));
  // After a corner (the blade now moves along x in a plane y = const, 90 degrees from
  // the last sweep) the earlier part no longer counts: vertex 0 is not reached.
  const SweptTriangles corner = {
    {{{Point{{0.1, 3, 2}}, Point{{0.1, 3, -1}}, Point{{0.5, 3, 2}}}},
     {{Point{{0.5, 3, 2}}, Point{{0.1, 3, -1}}, Point{{0.5, 3, -1}}}}}};
  tets.decisions->record_sweep(tets.all_cells(), corner);
  EXPECT_FALSE(tets.decisions->part_reaches(0, 0.2, current));
}
