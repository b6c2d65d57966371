// Exhaustive tests of the tetrahedron split lookup table (issue 4): all 64 edge codes in
// all 24 vertex orders, complete, partial and vertex cuts, on random and degenerate
// tetrahedra; consistency across a shared face; snapping; the interior-vertex case.

#include <lacerta/cut/split_table.h>

#include <gtest/gtest.h>

#include "cut_split_support.h"
#include <algorithm>
#include <array>
#include <map>
#include <numeric>
#include <random>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

using namespace lacerta::cut;
using namespace lacerta::cut::test_support;

namespace
{
  // Global ids realising each of the 24 orders of the four local vertices.
  std::vector<std::array<VertexId, 4>>
  all_orders()
  {
    std::vector<std::array<VertexId, 4>> orders;
    std::array<VertexId, 4>              rank{0, 1, 2, 3};
    do
      orders.push_back(
        {10 + 7 * rank[0], 10 + 7 * rank[1], 10 + 7 * rank[2], 10 + 7 * rank[3]});
    while (std::next_permutation(rank.begin(), rank.end()));
    return orders;
  }

  Mesh
  single_tet_mesh(const std::array<Point, 4> &x, const std::array<VertexId, 4> &ids)
  {
    // Mesh vertex ids are the global ids: points indexed by id.
    Mesh mesh;
    mesh.points.resize(*std::max_element(ids.begin(), ids.end()) + 1, Point{0, 0, 0});
    std::array<std::uint32_t, 4> t;
    for (unsigned v = 0; v < 4; ++v)
    {
      mesh.points[ids[v]] = x[v];
      t[v]                = static_cast<std::uint32_t>(ids[v]);
    }
    mesh.tets.push_back(t);
    return mesh;
  }

  bool
  node_on_face(const NodeRef &n, const unsigned f)
  {
    switch (n.kind)
    {
      case NodeKind::vertex:
        return n.index != f;
      case NodeKind::edge_point:
        return tet_edge_vertices[n.index][0] != f && tet_edge_vertices[n.index][1] != f;
      case NodeKind::face_point:
        return n.index == f;
      default:
        return false;
    }
  }

  // Checks one split; returns an empty string or what is wrong.
  std::string
  check_split(const TetCut      &cut,
              const SplitResult &r,
              const CutSurface  *surface,
              std::mt19937      &rng)
  {
    const auto  &x = cut.points;
    const double V = volume(x[0], x[1], x[2], x[3]);
    if (r.n_children == 0 || r.n_children > max_split_children)
      return "bad number of children";

    std::vector<std::array<Point, 4>> child(r.n_children);
    double                            sum = 0;
    for (unsigned c = 0; c < r.n_children; ++c)
    {
      child[c]       = child_node_points(cut, r, r.children[c]);
      const double v = volume(child[c][0], child[c][1], child[c][2], child[c][3]);
      if (!(v > 1e-9 * V))
        return "child " + std::to_string(c) + " not positively oriented";
      sum += v;
    }
    if (std::abs(sum - V) > 1e-12 * V)
      return "volumes do not add up: relative error " + std::to_string((sum - V) / V);

    // No overlap and no gap: random points of the parent lie in exactly one child.
    std::uniform_real_distribution<double> u(0, 1);
    for (unsigned k = 0; k < 32; ++k)
    {
      std::array<double, 4> b;
      double                s = 0;
      for (auto &w : b)
        s += (w = -std::log(u(rng) + 1e-300));
      Point q{0, 0, 0};
      for (unsigned v = 0; v < 4; ++v)
        q = add(q, scale(b[v] / s, x[v]));
      unsigned strictly = 0, loosely = 0;
      for (const auto &p : child)
      {
        const double                vol = signed_volume6(p[0], p[1], p[2], p[3]);
        const std::array<double, 4> l   = {signed_volume6(q, p[1], p[2], p[3]) / vol,
                                           signed_volume6(p[0], q, p[2], p[3]) / vol,
                                           signed_volume6(p[0], p[1], q, p[3]) / vol,
                                           signed_volume6(p[0], p[1], p[2], q) / vol};
        const double                m   = *std::min_element(l.begin(), l.end());
        strictly += m > 1e-9;
        loosely += m > -1e-9;
      }
      if (strictly > 1)
        return "children overlap";
      if (loosely == 0)
        return "children leave a gap";
    }

    // The children's faces on every parent face tile it.
    for (unsigned f = 0; f < 4; ++f)
    {
      double area = 0;
      for (unsigned c = 0; c < r.n_children; ++c)
        for (unsigned j = 0; j < 4; ++j)
        {
          bool on = true;
          for (unsigned k = 0; k < 4; ++k)
            if (k != j)
              on = on && node_on_face(r.children[c].nodes[k], f);
          if (on)
            area += triangle_area(child[c][(j + 1) % 4],
                                  child[c][(j + 2) % 4],
                                  child[c][(j + 3) % 4]);
        }
      const double expected =
        triangle_area(x[(f + 1) % 4], x[(f + 2) % 4], x[(f + 3) % 4]);
      if (std::abs(area - expected) > 1e-10 * expected)
        return "children do not tile face " + std::to_string(f);
    }

    if (surface == nullptr)
      return {};

    // Sides: a child lies on its side of the plane; separated copies agree with it.
    double size = 0;
    for (const auto &p : x)
      for (unsigned k = 0; k < 3; ++k)
        size = std::max(size, std::abs(p[k]));
    const double tol       = 1e-9 * size;
    const bool   separates = r.kind == CutKind::complete || r.kind == CutKind::partial;
    std::array<double, 3> cut_area{0, 0, 0};
    for (unsigned c = 0; c < r.n_children; ++c)
    {
      const Child &ch = r.children[c];
      if (r.kind == CutKind::complete && ch.side == 0)
        return "child of a complete cut without a side";
      for (unsigned k = 0; k < 4; ++k)
      {
        const NodeRef &n = ch.nodes[k];
        if (n.kind == NodeKind::edge_point && separates && n.side != ch.side)
          return "edge point copy from the other side";
        if (n.kind == NodeKind::face_point && n.side != 0)
          return "crack tip duplicated";
        if (ch.side != 0 && surface->plane(child[c][k]) * ch.side < -tol)
          return "child " + std::to_string(c) + " crosses the cut plane";
      }
      for (unsigned j = 0; j < 4; ++j)
        if (ch.cut_faces & (1u << j))
        {
          const Point &a = child[c][(j + 1) % 4], &b = child[c][(j + 2) % 4],
                      &d = child[c][(j + 3) % 4];
          if (std::abs(surface->plane(a)) > tol || std::abs(surface->plane(b)) > tol
              || std::abs(surface->plane(d)) > tol)
            return "cut face off the cut plane";
          cut_area[ch.side + 1] += triangle_area(a, b, d);
        }
    }
    if (separates)
    {
      std::vector<Point> corners;
      for (unsigned v = 0; v < 4; ++v)
        if (cut.vertex_side[v] == 0)
          corners.push_back(x[v]);
      for (unsigned e = 0; e < 6; ++e)
        if (cut.cut_edges & (1u << e))
          corners.push_back(r.edge_points[e]);
      for (unsigned f = 0; f < 4; ++f)
        if (cut.front_faces & (1u << f))
          corners.push_back(r.face_points[f]);
      const double area = convex_polygon_area(corners, surface->plane.normal);
      if (std::abs(cut_area[0] - area) > 1e-9 * area
          || std::abs(cut_area[2] - area) > 1e-9 * area || cut_area[1] != 0)
        return "cut faces do not cover the cut polygon on both sides";
    }
    return {};
  }

  // Corners of the section of the tetrahedron by a plane, counter-clockwise, with the
  // tetrahedron-face structure needed to draw fronts: (position, is a vertex).
  std::vector<std::pair<Point, bool>>
  section_corners(const std::array<Point, 4> &x,
                  const Plane                &plane,
                  const std::array<int, 4>   &side)
  {
    std::vector<std::pair<Point, bool>> c;
    for (unsigned v = 0; v < 4; ++v)
      if (side[v] == 0)
        c.push_back({x[v], true});
    for (const auto &e : tet_edge_vertices)
      if (side[e[0]] * side[e[1]] < 0)
      {
        const double di = plane(x[e[0]]), dj = plane(x[e[1]]);
        c.push_back({lerp(x[e[0]], x[e[1]], di / (di - dj)), false});
      }
    Point m{0, 0, 0};
    for (const auto &p : c)
      m = add(m, scale(1.0 / c.size(), p.first));
    const Point u = sub(c[0].first, m), w = cross(plane.normal, u);
    std::sort(c.begin(),
              c.end(),
              [&](const auto &a, const auto &b)
              {
                return std::atan2(dot(w, sub(a.first, m)), dot(u, sub(a.first, m)))
                       < std::atan2(dot(w, sub(b.first, m)), dot(u, sub(b.first, m)));
              });
    return c;
  }

  // Every way a plane can meet the tetrahedron (each pattern of vertex sides, with the
  // vertices on the plane exactly on it), as complete cuts, and for each the partial
  // cuts whose front crosses two section sides.
  std::vector<std::pair<CutSurface, bool>>
  cut_surfaces(const std::array<Point, 4> &x, std::mt19937 &rng)
  {
    std::uniform_real_distribution<double>   param(0.15, 0.85);
    std::vector<std::pair<CutSurface, bool>> result; // surface, is partial
    for (unsigned code = 0; code < 81; ++code)
    {
      std::array<int, 4> side;
      for (unsigned v = 0, c = code; v < 4; ++v, c /= 3)
        side[v] = static_cast<int>(c % 3) - 1;
      unsigned z = 0, off = 0;
      for (unsigned v = 0; v < 4; ++v)
        (side[v] == 0 ? z : off) |= 1u << v;
      if (off == 0 || side[__builtin_ctz(off)] < 0)
        continue;
      if ((off & ~0u)
          && std::all_of(side.begin(), side.end(), [](int s) { return s >= 0; }))
      {
        // The plane only touches the tetrahedron: through one vertex parallel to the
        // opposite face, through an edge parallel to the opposite edge, or a face.
        CutSurface            touch;
        std::vector<unsigned> on, rest;
        for (unsigned v = 0; v < 4; ++v)
          (side[v] == 0 ? on : rest).push_back(v);
        Point normal;
        if (on.empty())
          normal = sub(x[0], x[1]); // any plane missing the tetrahedron
        else if (on.size() == 1)
          normal = cross(sub(x[rest[1]], x[rest[0]]), sub(x[rest[2]], x[rest[0]]));
        else if (on.size() == 2)
          normal = cross(sub(x[on[1]], x[on[0]]), sub(x[rest[1]], x[rest[0]]));
        else
          normal = cross(sub(x[on[1]], x[on[0]]), sub(x[on[2]], x[on[0]]));
        touch.plane = {on.empty() ? add(x[0], sub(x[0], x[1])) : x[on[0]],
                       normalized(normal)};
        if (touch.plane(x[rest[0]]) < 0)
          touch.plane.normal = scale(-1, touch.plane.normal);
        result.push_back({touch, false});
        continue;
      }
      // Three points the plane passes through: vertices on it, then points on
      // crossing edges (or, for a plane that only touches, points outside).
      std::vector<Point> through;
      for (unsigned v = 0; v < 4; ++v)
        if (side[v] == 0)
          through.push_back(x[v]);
      std::vector<std::array<unsigned, 2>> crossing;
      for (const auto &e : tet_edge_vertices)
        if (side[e[0]] * side[e[1]] < 0)
          crossing.push_back(e);
      bool found = false;
      for (unsigned attempt = 0; attempt < 500 && !found; ++attempt)
      {
        std::vector<Point> p = through;
        for (std::size_t k = 0; p.size() < 3 && k < crossing.size(); ++k)
          p.push_back(lerp(x[crossing[k][0]], x[crossing[k][1]], param(rng)));
        Point centre{0, 0, 0};
        for (const auto &v : x)
          centre = add(centre, scale(0.25, v));
        std::uniform_real_distribution<double> far(-3, 3);
        while (p.size() < 3)
          p.push_back(add(p.empty() ? centre : p.back(), {far(rng), far(rng), far(rng)}));
        Plane plane{p[0], cross(sub(p[1], p[0]), sub(p[2], p[0]))};
        if (norm(plane.normal) < 1e-9)
          continue;
        plane.normal = normalized(plane.normal);
        bool ok      = true;
        for (unsigned v = 0; v < 4 && ok; ++v)
          if (side[v] != 0)
          {
            const double d = plane(x[v]);
            ok = d * side[v] * (plane(x[__builtin_ctz(off)]) > 0 ? 1 : -1) > 0;
          }
        if (!ok)
          continue;
        if (plane(x[__builtin_ctz(off)]) < 0)
          plane.normal = scale(-1, plane.normal);
        for (const auto &e : crossing)
        {
          const double di = plane(x[e[0]]), dj = plane(x[e[1]]);
          const double t = di / (di - dj);
          ok             = ok && t > 0.1 && t < 0.9;
        }
        if (!ok)
          continue;
        found = true;
        CutSurface complete;
        complete.plane = plane;
        result.push_back({complete, false});
        if (crossing.empty())
          continue;
        // Partial cuts: fronts through two section sides, either way round.
        const auto        c = section_corners(x, plane, side);
        const std::size_t m = c.size();
        for (std::size_t i = 0; i < m; ++i)
          for (std::size_t j = i + 1; j < m; ++j)
          {
            if ((c[i].second && c[(i + 1) % m].second)
                || (c[j].second && c[(j + 1) % m].second))
              continue; // a side along an edge
            const Point a = lerp(c[i].first, c[(i + 1) % m].first, param(rng));
            const Point b = lerp(c[j].first, c[(j + 1) % m].first, param(rng));
            for (const double s : {1.0, -1.0})
            {
              CutSurface partial;
              partial.plane     = plane;
              partial.has_front = true;
              partial.front = {a, scale(s, normalized(cross(plane.normal, sub(b, a))))};
              result.push_back({partial, true});
            }
          }
      }
      if (!found)
        ADD_FAILURE() << "no plane for side pattern " << code;
    }
    return result;
  }
} // namespace


TEST(CutSplitTable, EntriesHaveTheMinimalCounts)
{
  // Children per case; minimal by construction (exhaustive search, see the doc), and
  // well below the 17 of Bielser et al.'s fixed subdivision.
  const std::map<std::string, std::set<unsigned>> expected = {
    {"none", {1}},  {"touch-v", {1}}, {"touch-e", {1}}, {"touch-f", {1}}, {"A", {4}},
    {"B", {6}},     {"A-v", {3}},     {"A-vv", {2}},    {"C", {6}},       {"D", {8}},
    {"E", {9, 10}}, {"C-v", {5}},     {"D-v", {6}},     {"D-vv", {5}},    {"R1", {2}},
    {"R2", {3, 4}}, {"R3", {4, 5}},   {"R4", {5, 6}},   {"R5", {7}},      {"R6", {8}}};
  std::set<unsigned>              codes_with_entry;
  std::map<std::string, unsigned> per_case;
  for (const auto &e : split_table_entries())
  {
    const auto it = expected.find(e.name);
    ASSERT_NE(it, expected.end()) << "unexpected case " << e.name;
    EXPECT_TRUE(it->second.count(e.n_children))
      << e.name << " with " << e.n_children << " children";
    EXPECT_FALSE(e.uses_interior_point) << e.name;
    EXPECT_LE(e.n_children, max_split_children);
    codes_with_entry.insert(e.cut_edges);
    ++per_case[e.name];
  }
  EXPECT_EQ(codes_with_entry.size(), 64u);
  // Subcases in the canonical frame: the vertex order decides them.
  EXPECT_EQ(per_case["A"], 4u);     // the lone vertex is 1st, 2nd, 3rd or 4th
  EXPECT_EQ(per_case["B"], 3u * 2); // which edge pair stays, times two cut diagonals
  EXPECT_EQ(per_case["C"], 6u);
  EXPECT_EQ(per_case["D"], 12u);
  EXPECT_EQ(per_case["E"], 12u);
}


TEST(CutSplitTable, DiagonalRuleIsThePapersAndSymmetric)
{
  // Quad p0, p1, a, b of face (p0, p1, z), a on p1-z, b on p0-z: diagonal p0-a iff p0 or
  // b is the smallest. Relabelling the quad (p0 <-> p1, a <-> b) must give the same
  // diagonal, or the two tetrahedra sharing the face would disagree.
  const std::array<VertexId, 3> ids{4, 9, 17};
  std::array<unsigned, 3>       perm{0, 1, 2};
  do
  {
    const VertexId p0 = ids[perm[0]], p1 = ids[perm[1]], z = ids[perm[2]];
    using K = std::array<VertexId, 2>;
    const K k_p0{p0, p0}, k_p1{p1, p1}, k_a{std::min(p1, z), std::max(p1, z)},
      k_b{std::min(p0, z), std::max(p0, z)};
    const K smallest = std::min({k_p0, k_p1, k_a, k_b});
    EXPECT_EQ(quad_diagonal_through_first(p0, p1, z),
              smallest == k_p0 || smallest == k_b);
    EXPECT_NE(quad_diagonal_through_first(p0, p1, z),
              quad_diagonal_through_first(p1, p0, z));
    EXPECT_EQ(diagonal_order_key(p0, z), diagonal_order_key(z, p0));
  } while (std::next_permutation(perm.begin(), perm.end()));
}


TEST(CutSplitTable, PapersRuleNeverTwistsTheCompleteCutPrisms)
{
  // The claim of doc/split-table.md: under the paper's rule (quad p0, p1, a, b split by
  // p0-a iff p0 or b is the smallest) with any one total order of the points, the prism
  // of case A never twists (all 720 orders of its six points), and the two prisms of
  // case B never forbid both diagonals of the cut quadrilateral (all 40320 orders of
  // its eight points). So no complete cut needs an interior vertex.
  // The vertex of the quad p0, p1, a, b the rule's diagonal passes through:
  const auto through =
    [](const std::array<unsigned, 8> &r, unsigned p0, unsigned p1, unsigned a, unsigned b)
  {
    const unsigned m = std::min({r[p0], r[p1], r[a], r[b]});
    return (m == r[p0] || m == r[b]) ? p0 : p1;
  };
  // Case A: apex 0, base 1, 2, 3; points 4, 5, 6 on the edges 0-1, 0-2, 0-3.
  std::array<unsigned, 8> r{0, 1, 2, 3, 4, 5, 6, 7};
  unsigned                orders = 0;
  do
  {
    std::array<unsigned, 3> starts{}; // how many diagonals each base vertex starts
    for (const auto &q : std::array<std::array<unsigned, 2>, 3>{{{1, 2}, {2, 3}, {3, 1}}})
      ++starts[through(r, q[0], q[1], 3 + q[1], 3 + q[0]) - 1];
    EXPECT_NE(starts, (std::array<unsigned, 3>{1, 1, 1})) << "twisted prism";
    ++orders;
  } while (std::next_permutation(r.begin(), r.begin() + 7));
  EXPECT_EQ(orders, 5040u); // all orders of apex, base and cut points
  // Case B: {0,1} | {2,3}; points 4 = q02, 5 = q03, 6 = q12, 7 = q13.
  std::iota(r.begin(), r.end(), 0u);
  do
  {
    const unsigned a1 = through(r, 0, 1, 6, 4),
                   a2 = through(r, 0, 1, 7, 5); // faces 012, 013
    const unsigned b1 = through(r, 2, 3, 5, 4),
                   b2 = through(r, 2, 3, 7, 6); // faces 023, 123
    // A prism twists with the cut diagonal q02-q13 if its face diagonals go 0 and 1
    // (resp. 2 and 3), with q03-q12 if they go 1 and 0 (resp. 3 and 2).
    const int forbidden_a = a1 == a2 ? 0 : (a1 == 0 ? 1 : 2);
    const int forbidden_b = b1 == b2 ? 0 : (b1 == 2 ? 1 : 2);
    EXPECT_FALSE(forbidden_a != 0 && forbidden_b != 0 && forbidden_a != forbidden_b);
  } while (std::next_permutation(r.begin(), r.end()));
}


TEST(CutSplitTable, AllCodesAllOrdersAllShapes)
{
  std::mt19937                           rng(7);
  const auto                             orders  = all_orders();
  const std::vector<Shape>               shapes  = {Shape::random,
                                                    Shape::random,
                                                    Shape::random,
                                                    Shape::random,
                                                    Shape::needle,
                                                    Shape::sliver,
                                                    Shape::cap,
                                                    Shape::wedge};
  const auto                            &entries = split_table_entries();
  std::uniform_real_distribution<double> param(0.1, 0.9);
  SplitResult                            r;
  for (const Shape shape : shapes)
  {
    const auto x = make_tetrahedron(shape, rng);
    for (std::size_t o = 0; o < orders.size(); ++o)
    {
      const auto             &ids = orders[o];
      std::set<std::string>   hit; // cases and codes seen in this order
      std::set<std::uint16_t> entries_hit;
      // Refinements: every code, no separation.
      for (unsigned code = 0; code < 64; ++code)
      {
        TetCut cut;
        cut.vertex_ids = ids;
        cut.points     = x;
        cut.vertex_side.fill(1);
        cut.cut_edges = static_cast<std::uint8_t>(code);
        for (auto &t : cut.edge_parameter)
          t = param(rng);
        const CutKind kind = split_tetrahedron(cut, r);
        ASSERT_EQ(kind, code == 0 ? CutKind::none : CutKind::refinement);
        const std::string error = check_split(cut, r, nullptr, rng);
        ASSERT_TRUE(error.empty())
          << shape_name(shape) << " order " << o << " code " << code << ": " << error;
        entries_hit.insert(r.entry);
      }
      // Every plane section, complete and partial.
      for (const auto &[surface, partial] : cut_surfaces(x, rng))
      {
        const Mesh mesh = single_tet_mesh(x, ids);
        const auto a    = analyse(mesh, surface, default_snap_fraction);
        if (a.cuts.empty())
          continue; // the plane misses the tetrahedron
        const TetCut &cut  = a.cuts.front();
        const CutKind kind = split_tetrahedron(cut, r);
        ASSERT_EQ(kind == CutKind::partial, partial)
          << shape_name(shape) << " order " << o << ": kind " << int(kind);
        ASSERT_NE(kind, CutKind::unsupported);
        ASSERT_NE(kind, CutKind::refinement);
        const std::string error = check_split(cut, r, &surface, rng);
        ASSERT_TRUE(error.empty()) << shape_name(shape) << " order " << o << " case "
                                   << entries[r.entry].name << ": " << error;
        entries_hit.insert(r.entry);
      }
      // Every entry of the table (in the canonical frame, which this order maps to
      // a different local configuration) must have been used; for case B either
      // diagonal variant.
      for (std::size_t k = 0; k < entries.size(); ++k)
      {
        const auto &e = entries[k];
        if (e.variant == 1)
          continue;
        bool used = entries_hit.count(static_cast<std::uint16_t>(k)) > 0;
        if (e.name == "B")
          used = used || entries_hit.count(static_cast<std::uint16_t>(k + 1)) > 0;
        EXPECT_TRUE(used) << "entry " << k << " (" << e.name
                          << ") not exercised in order " << o << " on "
                          << shape_name(shape);
      }
    }
  }
}


TEST(CutSplitTable, FaceAdjacentTetrahedraAgreeOnTheSharedFace)
{
  // Tetrahedra (0,1,2,3) and (0,2,1,4) share the face (0,1,2). Every order of the five
  // global ids; cuts by planes (complete and partial) and arbitrary compatible codes.
  std::mt19937                           rng(11);
  std::uniform_real_distribution<double> u(-1, 1), param(0.1, 0.9);
  const std::array<Point, 5>             x = {
                {{0, 0, 0}, {1, 0.1, 0}, {0.2, 1, 0.1}, {0.3, 0.4, 0.9}, {0.4, 0.2, -0.8}}};
  std::array<std::uint32_t, 5> rank{0, 1, 2, 3, 4};
  SplitResult                  r;
  unsigned                     compared = 0;
  do
  {
    Mesh mesh;
    mesh.points.resize(5);
    std::array<std::uint32_t, 5> id;
    for (unsigned v = 0; v < 5; ++v)
    {
      id[v]              = rank[v];
      mesh.points[id[v]] = x[v];
    }
    mesh.tets = {{id[0], id[1], id[2], id[3]}, {id[0], id[2], id[1], id[4]}};
    const auto shared_faces = [&](const TetCut &cut, const SplitResult &res)
    {
      // The child faces lying on the shared face, as sorted point keys.
      std::set<std::array<PointKey, 3>> faces;
      unsigned                          f = 0;
      while (cut.vertex_ids[f] == id[0] || cut.vertex_ids[f] == id[1]
             || cut.vertex_ids[f] == id[2])
        ++f;
      for (unsigned c = 0; c < res.n_children; ++c)
        for (unsigned j = 0; j < 4; ++j)
        {
          std::array<PointKey, 3> k;
          bool                    on = true;
          for (unsigned i = 0, n = 0; i < 4; ++i)
            if (i != j)
            {
              on     = on && node_on_face(res.children[c].nodes[i], f);
              k[n++] = point_key(cut.vertex_ids, res.children[c].nodes[i], 0);
            }
          if (on)
          {
            std::sort(k.begin(), k.end());
            EXPECT_TRUE(faces.insert(k).second) << "face produced twice";
          }
        }
      return faces;
    };

    // Planes through the shared face region, some through its vertices.
    for (unsigned k = 0; k < 40; ++k)
    {
      CutSurface  s;
      const Point through =
        k % 4 == 0 ? x[k / 4 % 3]
                   : Point{0.3 + 0.3 * u(rng), 0.3 + 0.3 * u(rng), 0.1 * u(rng)};
      s.plane = {through, normalized({u(rng), u(rng), u(rng)})};
      if (k % 2 == 1)
      {
        s.has_front = true;
        s.front     = {Point{0.35 + 0.2 * u(rng), 0.3 + 0.2 * u(rng), 0.0},
                       normalized(cross(s.plane.normal, {u(rng), u(rng), u(rng)}))};
      }
      const auto a = analyse(mesh, s, default_snap_fraction);
      if (a.cuts.size() != 2)
        continue;
      std::array<std::set<std::array<PointKey, 3>>, 2> faces;
      for (unsigned t = 0; t < 2; ++t)
      {
        ASSERT_NE(split_tetrahedron(a.cuts[t], r), CutKind::unsupported);
        faces[t] = shared_faces(a.cuts[t], r);
      }
      ASSERT_EQ(faces[0], faces[1]) << "plane " << k;
      ++compared;
    }

    // All 2^9 compatible edge codes as refinements, one parameter per mesh edge.
    std::map<std::pair<std::uint32_t, std::uint32_t>, unsigned> edge_index;
    for (const auto &t : mesh.tets)
      for (const auto &e : tet_edge_vertices)
        edge_index.emplace(std::make_pair(std::min(t[e[0]], t[e[1]]),
                                          std::max(t[e[0]], t[e[1]])),
                           static_cast<unsigned>(edge_index.size()));
    std::vector<double> t_of_edge(edge_index.size());
    for (unsigned code = 0; code < (1u << edge_index.size()); ++code)
    {
      for (auto &t : t_of_edge)
        t = param(rng);
      std::array<std::set<std::array<PointKey, 3>>, 2> faces;
      for (unsigned k = 0; k < 2; ++k)
      {
        TetCut cut;
        for (unsigned v = 0; v < 4; ++v)
        {
          cut.vertex_ids[v] = mesh.tets[k][v];
          cut.points[v]     = mesh.points[mesh.tets[k][v]];
        }
        cut.vertex_side.fill(1);
        for (unsigned e = 0; e < 6; ++e)
        {
          const std::uint32_t i = mesh.tets[k][tet_edge_vertices[e][0]],
                              j = mesh.tets[k][tet_edge_vertices[e][1]];
          const unsigned index  = edge_index.at({std::min(i, j), std::max(i, j)});
          if (code & (1u << index))
          {
            cut.cut_edges |= static_cast<std::uint8_t>(1u << e);
            cut.edge_parameter[e] = t_of_edge[index];
          }
        }
        split_tetrahedron(cut, r);
        faces[k] = shared_faces(cut, r);
      }
      ASSERT_EQ(faces[0], faces[1]) << "code " << code;
      ++compared;
    }
  } while (std::next_permutation(rank.begin(), rank.end()));
  EXPECT_GT(compared, 120u * 512u);
}


TEST(CutSplitTable, SnappingKeepsNewEdgesLong)
{
  // Planes anywhere and close to vertices (or exactly through them). After snapping no
  // cut point is closer than eps*|edge| to an end of its edge, cuts through vertices
  // work, and every new edge of a complete cut is at least eps * (shortest parent
  // edge) * min(1, sin(smallest face angle)): two cut points near a common vertex are
  // that far apart, and the cut quadrilateral is split by its longer diagonal.
  std::mt19937                           rng(3);
  std::uniform_real_distribution<double> u(-1, 1);
  SplitResult                            r;
  unsigned                               snapped = 0;
  for (const double eps : {0.01, default_snap_fraction, 0.2})
    for (const Shape shape :
         {Shape::random, Shape::needle, Shape::cap, Shape::wedge, Shape::sliver})
      for (unsigned k = 0; k < 600; ++k)
      {
        const auto                    x   = make_tetrahedron(shape, rng);
        const std::array<VertexId, 4> ids = all_orders()[k % 24];
        const unsigned                v   = k % 4;
        Point                         c   = x[v];
        if (k % 3 == 1)
          for (unsigned w = 0; w < 4; ++w) // near a vertex
            c = add(c, scale(0.1 * eps * (u(rng) + 1), sub(x[w], x[v])));
        else if (k % 3 == 2)
          for (unsigned w = 0; w < 4; ++w) // anywhere inside
            c = add(c, scale(0.25 * (u(rng) + 1), sub(x[w], x[v])));
        CutSurface s;
        s.plane      = {c, normalized({u(rng), u(rng), u(rng)})};
        const auto a = analyse(single_tet_mesh(x, ids), s, eps);
        if (a.cuts.empty())
          continue;
        const TetCut &cut  = a.cuts.front();
        const CutKind kind = split_tetrahedron(cut, r, eps);
        ASSERT_NE(kind, CutKind::unsupported);
        ASSERT_NE(kind, CutKind::refinement);
        for (unsigned w = 0; w < 4; ++w)
          snapped += cut.vertex_side[w] == 0 && (k % 3 == 1);
        // The snapped cut surface differs from the plane by up to eps*|edge|, so the
        // sides are checked combinatorially.
        const std::string error = check_split(cut, r, nullptr, rng);
        ASSERT_TRUE(error.empty()) << error;
        for (unsigned c2 = 0; c2 < r.n_children; ++c2)
        {
          const Child &ch = r.children[c2];
          if (kind == CutKind::complete)
          {
            ASSERT_NE(ch.side, 0);
          }
          for (const NodeRef &n : ch.nodes)
            if (n.kind == NodeKind::vertex && cut.vertex_side[n.index] != 0)
            {
              ASSERT_EQ(cut.vertex_side[n.index], ch.side);
            }
        }
        double shortest = 1e300, sine = 1;
        for (const auto &e : tet_edge_vertices)
          shortest = std::min(shortest, norm(sub(x[e[0]], x[e[1]])));
        for (unsigned f = 0; f < 4; ++f)
          for (unsigned w = 0; w < 4; ++w)
            if (w != f)
            {
              std::array<unsigned, 2> o;
              for (unsigned i = 0, n = 0; i < 4; ++i)
                if (i != f && i != w)
                  o[n++] = i;
              const Point  a1 = sub(x[o[0]], x[w]), a2 = sub(x[o[1]], x[w]);
              const double cosine = dot(a1, a2) / (norm(a1) * norm(a2));
              if (cosine > 0)
                sine = std::min(sine, std::sqrt(1 - cosine * cosine));
            }
        for (unsigned e = 0; e < 6; ++e)
          if (cut.cut_edges & (1u << e))
          {
            const double length =
              norm(sub(x[tet_edge_vertices[e][0]], x[tet_edge_vertices[e][1]]));
            for (const unsigned end : tet_edge_vertices[e])
              EXPECT_GE(norm(sub(r.edge_points[e], x[end])), eps * length * (1 - 1e-12));
          }
        EXPECT_GE(shortest_child_edge(cut, r), eps * shortest * sine * (1 - 1e-12))
          << shape_name(shape) << " eps " << eps << " case "
          << split_table_entries()[r.entry].name;
      }
  EXPECT_GT(snapped, 100u); // the planes near vertices did snap
}


TEST(CutSplitTable, RejectsBadInput)
{
  TetCut cut;
  cut.vertex_ids = {1, 2, 3, 4};
  cut.points     = {{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}}};
  cut.vertex_side.fill(1);
  SplitResult r;
  EXPECT_EQ(split_tetrahedron(cut, r), CutKind::none);
  EXPECT_THROW(split_tetrahedron(cut, r, 0.5), std::invalid_argument);
  EXPECT_THROW(split_tetrahedron(cut, r, 0.0), std::invalid_argument);
  cut.vertex_ids = {1, 2, 2, 4};
  EXPECT_THROW(split_tetrahedron(cut, r), std::invalid_argument);
  // Front points that describe no partial cut: nothing is done.
  cut.vertex_ids  = {1, 2, 3, 4};
  cut.front_faces = 0b0001;
  EXPECT_EQ(split_tetrahedron(cut, r), CutKind::unsupported);
  EXPECT_EQ(r.n_children, 0u);
}


TEST(CutSplitTable, TwistedPrismNeedsAnInteriorVertex)
{
  // The paper's Figure 3: a prism whose three quadrilateral diagonals twist around it
  // (Schönhardt) has no tetrahedralisation with its own vertices; the decomposition
  // detects it and adds one vertex at the prism's centroid. The same prism with
  // diagonals from the global-order rule needs none.
  for (const bool twisted : {false, true})
  {
    PieceProblem          p;
    std::array<Point, 32> s{};
    for (unsigned i = 0; i < 3; ++i)
    {
      const double a = 2.0943951023931953 * i;
      s[i]           = {std::cos(a), std::sin(a), 0};
      s[3 + i]       = {std::cos(a), std::sin(a), 1};
    }
    const Point centre{0, 0, 0.5};
    const auto  add_triangle = [&](PieceNode a, PieceNode b, PieceNode c)
    {
      if (signed_volume6(s[a], s[b], s[c], centre) > 0)
        p.boundary.push_back({a, b, c});
      else
        p.boundary.push_back({a, c, b});
    };
    p.nodes = {0, 1, 2, 3, 4, 5};
    add_triangle(0, 1, 2);
    add_triangle(3, 4, 5);
    for (unsigned i = 0; i < 3; ++i)
    {
      const PieceNode a  = static_cast<PieceNode>(i),
                      b  = static_cast<PieceNode>((i + 1) % 3);
      const unsigned bit = 4u << i;
      p.plane_mask[a] |= bit;
      p.plane_mask[b] |= bit;
      p.plane_mask[a + 3] |= bit;
      p.plane_mask[b + 3] |= bit;
      if (twisted || i != 2)
      {
        add_triangle(a, b, b + 3); // diagonal a-(b+3): each vertex starts one
        add_triangle(a, b + 3, a + 3);
      }
      else
      {
        add_triangle(a, b, a + 3);
        add_triangle(b, b + 3, a + 3);
      }
    }
    for (unsigned i = 0; i < 3; ++i)
    {
      p.plane_mask[i] |= 1;
      p.plane_mask[i + 3] |= 2;
    }
    p.samples.push_back(s);
    EXPECT_EQ(minimal_tetrahedralization(p, 12).has_value(), !twisted);
    const PieceDecomposition d = decompose_piece(p, 12);
    EXPECT_EQ(d.uses_interior_node, twisted);
    EXPECT_EQ(d.tetrahedra.size(), twisted ? 8u : 3u);
    double total    = 0;
    s[steiner_node] = centre;
    for (const auto &t : d.tetrahedra)
    {
      const double v = signed_volume6(s[t[0]], s[t[1]], s[t[2]], s[t[3]]) / 6;
      EXPECT_GT(v, 0);
      total += v;
    }
    EXPECT_NEAR(total, 3 * std::sqrt(3.0) / 4, 1e-12); // prism volume
  }
}
