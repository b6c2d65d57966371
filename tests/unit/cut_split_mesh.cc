// Mesh-level tests of the split table: a structured mesh of thousands of tetrahedra cut
// by random planes, planes through vertices and along faces, partial cuts, and
// progressive cuts compared with one stroke. The cutting itself is the minimal cutter of
// cut_split_support.h, built on the table's public interface.

#include <lacerta/cut/split_table.h>

#include <gtest/gtest.h>

#include "cut_split_support.h"
#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <random>
#include <string>
#include <vector>

using namespace lacerta::cut;
using namespace lacerta::cut::test_support;

namespace
{
  // Area of the boundary faces of the mesh that lie on a plane (both sheets of a cut).
  double
  boundary_area_on_plane(const Mesh &mesh, const Plane &plane)
  {
    std::map<std::array<std::uint32_t, 3>, unsigned> count;
    for (const auto &t : mesh.tets)
      for (unsigned f = 0; f < 4; ++f)
        ++count[sorted(t[(f + 1) % 4], t[(f + 2) % 4], t[(f + 3) % 4])];
    double area = 0;
    for (const auto &[f, c] : count)
    {
      const Point &a = mesh.points[f[0]], &b = mesh.points[f[1]], &d = mesh.points[f[2]];
      if (c == 1 && std::abs(plane(a)) < 1e-9 && std::abs(plane(b)) < 1e-9
          && std::abs(plane(d)) < 1e-9)
        area += triangle_area(a, b, d);
    }
    return area;
  }

  // The largest distance by which a tetrahedron reaches across a plane to the side
  // where it does not belong (0 if it lies on one side).
  double
  largest_crossing(const Mesh &mesh, const Plane &plane)
  {
    double worst = 0;
    for (const auto &t : mesh.tets)
    {
      double lo = 0, hi = 0;
      for (const auto v : t)
      {
        lo = std::min(lo, plane(mesh.points[v]));
        hi = std::max(hi, plane(mesh.points[v]));
      }
      worst = std::max(worst, std::min(-lo, hi));
    }
    return worst;
  }

  Plane
  plane_through(const Point &a, const Point &b, const Point &c)
  {
    return {a, normalized(cross(sub(b, a), sub(c, a)))};
  }
} // namespace


TEST(CutSplitMesh, PlanesThroughVerticesAndAlongFacesGiveExactHalves)
{
  // Planes that pass through mesh vertices, along mesh faces and through edges: the two
  // halves come out exactly (no snapping is involved), with the full section as crack.
  struct Case
  {
    Plane  plane;
    double smaller_volume;
    double section_area;
  };
  const double            s3    = std::sqrt(3.0);
  const std::vector<Case> cases = {
    {{{0.375, 0, 0}, {1, 0, 0}}, 0.375, 1.0},                    // along faces
    {{{0, 0, 0}, normalized({1, -1, 0})}, 0.5, std::sqrt(2.0)},  // along Kuhn faces
    {{{0.5, 0.5, 0.5}, normalized({1, 1, 1})}, 0.5, 3 * s3 / 4}, // through vertices
    {{{0.25, 0, 0}, normalized({1, 1, 0})}, 0.03125, 0.25 * std::sqrt(2.0)}}; // corner
  std::mt19937 rng(1);
  for (const auto &c : cases)
  {
    Mesh mesh = box_mesh(8, rng);
    ASSERT_EQ(mesh.tets.size(), 3072u);
    CutSurface s;
    s.plane                   = c.plane;
    const CutStatistics stats = cut_mesh(mesh, s, default_snap_fraction);
    EXPECT_EQ(stats.unsupported, 0u);
    EXPECT_GT(stats.split_tets, 0u);
    EXPECT_EQ(conformity_error(mesh, on_box_boundary, {c.plane}), "");
    EXPECT_NEAR(mesh_volume(mesh), 1.0, 1e-12);
    EXPECT_GT(min_tet_volume(mesh), 0);
    const auto parts = component_volumes(mesh);
    ASSERT_EQ(parts.size(), 2u);
    EXPECT_NEAR(parts[0], c.smaller_volume, 1e-12);
    EXPECT_NEAR(parts[1], 1 - c.smaller_volume, 1e-12);
    EXPECT_NEAR(boundary_area_on_plane(mesh, c.plane), 2 * c.section_area, 1e-12);
    EXPECT_LE(largest_crossing(mesh, c.plane), 1e-15);
  }
}


TEST(CutSplitMesh, RandomPlanesKeepTheMeshConforming)
{
  // Three successive cuts per mesh (random planes, and planes through three random
  // mesh vertices), crossing each other.
  std::mt19937                           rng(2);
  std::uniform_real_distribution<double> u(0, 1), w(-1, 1);
  const double                           longest_edge = std::sqrt(3.0) / 8;
  const double snap_tolerance = default_snap_fraction * longest_edge;
  for (unsigned run = 0; run < 4; ++run)
  {
    Mesh               mesh = box_mesh(8, rng);
    std::vector<Plane> planes;
    std::size_t        split = 0;
    for (unsigned k = 0; k < 3; ++k)
    {
      Plane plane;
      if ((run + k) % 2 == 0)
        plane = {{0.2 + 0.6 * u(rng), 0.2 + 0.6 * u(rng), 0.2 + 0.6 * u(rng)},
                 normalized({w(rng), w(rng), w(rng)})};
      else
      {
        // Through three original vertices (ids below 729 are the grid's).
        std::uniform_int_distribution<std::uint32_t> vertex(0, 728);
        do
          plane = plane_through(mesh.points[vertex(rng)],
                                mesh.points[vertex(rng)],
                                mesh.points[vertex(rng)]);
        while (!(std::abs(plane({0.5, 0.5, 0.5})) < 0.3));
      }
      planes.push_back(plane);
      CutSurface s;
      s.plane                   = plane;
      s.id                      = static_cast<int>(k);
      const CutStatistics stats = cut_mesh(mesh, s, default_snap_fraction);
      split += stats.split_tets;
      ASSERT_EQ(stats.unsupported, 0u);
      ASSERT_EQ(conformity_error(mesh, on_box_boundary, planes, snap_tolerance), "")
        << "run " << run << " cut " << k;
      ASSERT_NEAR(mesh_volume(mesh), 1.0, 1e-12);
      ASSERT_GT(min_tet_volume(mesh), 0);
      if (k == 0)
      {
        EXPECT_EQ(component_volumes(mesh).size(), 2u);
      }
      // Snapping moves the cut surface by at most eps times an edge.
      for (const auto &p : planes)
        EXPECT_LE(largest_crossing(mesh, p), default_snap_fraction * longest_edge);
    }
    EXPECT_GT(split, 300u);
    EXPECT_GT(component_volumes(mesh).size(), 3u);
  }
}


TEST(CutSplitMesh, PartialCutOpensACrackAndKeepsTheTipConnected)
{
  std::mt19937 rng(4);
  const Plane  plane{{0.47, 0, 0}, normalized({1, 0.3, 0})};
  CutSurface   partial;
  partial.plane     = plane;
  partial.has_front = true;
  partial.front     = {{0, 0.55, 0}, {0, 1, 0}}; // the crack is where y < 0.55
  CutSurface complete;
  complete.plane = plane;

  const double snap_tolerance = default_snap_fraction * std::sqrt(3.0) / 6;
  Mesh         mesh           = box_mesh(6, rng);
  ASSERT_EQ(cut_mesh(mesh, partial, default_snap_fraction).unsupported, 0u);
  EXPECT_EQ(conformity_error(mesh, on_box_boundary, {plane}, snap_tolerance), "");
  EXPECT_NEAR(mesh_volume(mesh), 1.0, 1e-12);
  EXPECT_GT(min_tet_volume(mesh), 0);
  EXPECT_EQ(component_volumes(mesh).size(), 1u); // connected ahead of the front
  const double crack = 0.55 * std::sqrt(1.09);   // the plane's part with y < 0.55
  EXPECT_NEAR(boundary_area_on_plane(mesh, plane), 2 * crack, 0.02 * crack);

  // Completing the cut separates exactly what one stroke separates.
  ASSERT_EQ(cut_mesh(mesh, complete, default_snap_fraction).unsupported, 0u);
  EXPECT_EQ(conformity_error(mesh, on_box_boundary, {plane}, snap_tolerance), "");
  Mesh one_stroke = box_mesh(6, rng);
  cut_mesh(one_stroke, complete, default_snap_fraction);
  const auto progressive = component_volumes(mesh),
             reference   = component_volumes(one_stroke);
  ASSERT_EQ(progressive.size(), 2u);
  ASSERT_EQ(reference.size(), 2u);
  EXPECT_NEAR(progressive[0], reference[0], 1e-12);
  EXPECT_NEAR(progressive[1], reference[1], 1e-12);
  EXPECT_NEAR(progressive[0], 0.32, 0.01); // x + 0.3 y < 0.47, up to snapping
  EXPECT_NEAR(boundary_area_on_plane(mesh, plane),
              boundary_area_on_plane(one_stroke, plane),
              1e-12);
}


TEST(CutSplitMesh, ProgressiveCutMatchesOneStroke)
{
  // A blade sweeping a plane, cut in many small steps (each a partial cut whose front
  // has moved on), separates the same geometry as one complete cut: one tetrahedron of
  // every shape, and a small patch of the structured mesh.
  std::mt19937                           rng(5);
  std::uniform_real_distribution<double> u(-1, 1);
  unsigned                               partial_splits = 0, compared = 0;
  for (unsigned run = 0; run < 62; ++run)
  {
    Mesh       mesh;
    const bool special = run >= 60; // along mesh faces; through vertices
    const bool patch   = run % 5 == 4;
    if (special)
      mesh = box_mesh(3, rng);
    else if (patch)
      mesh = box_mesh(2, rng);
    else
    {
      const Shape shapes[] = {
        Shape::random, Shape::needle, Shape::sliver, Shape::cap, Shape::wedge};
      const auto                   x = make_tetrahedron(shapes[(run / 5) % 5], rng);
      std::array<std::uint32_t, 4> ids{0, 1, 2, 3};
      std::shuffle(ids.begin(), ids.end(), rng);
      mesh.points = {x[ids[0]], x[ids[1]], x[ids[2]], x[ids[3]]};
      std::array<std::uint32_t, 4> t{0, 1, 2, 3};
      if (volume(mesh.points[0], mesh.points[1], mesh.points[2], mesh.points[3]) < 0)
        std::swap(t[0], t[1]);
      mesh.tets = {t};
    }
    const Mesh original = mesh;
    // Boundary of the original domain: faces on the original boundary planes.
    std::vector<Plane> outer;
    {
      std::map<std::array<std::uint32_t, 3>, unsigned> count;
      for (const auto &t : original.tets)
        for (unsigned f = 0; f < 4; ++f)
          ++count[sorted(t[(f + 1) % 4], t[(f + 2) % 4], t[(f + 3) % 4])];
      for (const auto &[f, c] : count)
        if (c == 1)
          outer.push_back(plane_through(original.points[f[0]],
                                        original.points[f[1]],
                                        original.points[f[2]]));
    }
    const auto on_outer = [&](const std::array<Point, 3> &p)
    {
      for (const auto &o : outer)
        if (std::abs(o(p[0])) < 1e-9 && std::abs(o(p[1])) < 1e-9
            && std::abs(o(p[2])) < 1e-9)
          return true;
      return false;
    };

    // A plane through an interior point; the blade moves along m within the plane.
    Point centre{0, 0, 0};
    for (const auto &p : original.points)
      centre = add(centre, scale(1.0 / original.points.size(), p));
    double radius = 0, longest = 0;
    for (const auto &p : original.points)
      radius = std::max(radius, norm(sub(p, centre)));
    for (const auto &t : original.tets)
      for (const auto &e : tet_edge_vertices)
        longest = std::max(longest,
                           norm(sub(original.points[t[e[0]]], original.points[t[e[1]]])));
    CutSurface s;
    s.plane = {add(centre, scale(0.2 * radius, {u(rng), u(rng), u(rng)})),
               normalized({u(rng), u(rng), u(rng)})};
    if (run == 60)
      s.plane = {{1.0 / 3, 0, 0}, {1, 0, 0}};
    if (run == 61)
      s.plane = {{0.5, 0.5, 0.5}, normalized({1, 1, 1})};
    const Point m = normalized(cross(s.plane.normal, {u(rng), u(rng), u(rng)}));

    Mesh one_stroke = original;
    cut_mesh(one_stroke, s, default_snap_fraction);
    const auto reference = component_volumes(one_stroke);
    if (reference.size() != 2)
      continue; // the plane missed the domain

    const unsigned steps = 7;
    s.has_front          = true;
    for (unsigned k = 1; k <= steps + 1; ++k)
    {
      s.front = {add(centre, scale(radius * (-1.0 + 2.0 * k / steps), m)), m};
      const CutStatistics stats = cut_mesh(mesh, s, default_snap_fraction);
      ASSERT_EQ(stats.unsupported, 0u) << "run " << run << " step " << k;
      ASSERT_EQ(
        conformity_error(mesh, on_outer, {s.plane}, default_snap_fraction * longest), "")
        << "run " << run << " step " << k;
      ASSERT_NEAR(mesh_volume(mesh),
                  mesh_volume(original),
                  1e-12 * mesh_volume(original));
      ASSERT_GT(min_tet_volume(mesh), 0);
      partial_splits += stats.partial;
      if (stats.partial
          > 0) // a crack front inside: the tip keeps the domain in one piece
      {
        ASSERT_EQ(component_volumes(mesh).size(), 1u) << "run " << run << " step " << k;
      }
    }
    ++compared;
    const auto progressive = component_volumes(mesh);
    ASSERT_EQ(progressive.size(), 2u) << "run " << run;
    const double v = mesh_volume(original);
    EXPECT_NEAR(progressive[0], reference[0], 1e-12 * v) << "run " << run;
    EXPECT_NEAR(progressive[1], reference[1], 1e-12 * v) << "run " << run;
    EXPECT_NEAR(boundary_area_on_plane(mesh, s.plane),
                boundary_area_on_plane(one_stroke, s.plane),
                1e-10 * v / radius);
  }
  EXPECT_GT(partial_splits, 100u);
  EXPECT_GE(compared, 55u); // a plane through an interior point rarely misses
}
