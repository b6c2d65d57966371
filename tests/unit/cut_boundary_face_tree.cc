// The boundary face tree (first contact of the scalpel) on a deforming mesh: its
// answers against a search of every boundary face, and its refits.
#include <lacerta/cut/boundary_face_tree.h>

#include <gtest/gtest.h>

#include "cut_split_support.h"
#include <algorithm>
#include <cmath>
#include <random>
#include <set>
#include <tuple>
#include <vector>

namespace
{
  using namespace lacerta;
  using cut::BoundaryFaceTree;
  using cut::Box;

  /// A face as (tet, face), for comparing sets of answers.
  using FaceKey = std::pair<unsigned int, unsigned int>;

  using cut::test_support::box_tet_mesh;

  /// The faces a query of @p box must give: every boundary face whose box at @p x
  /// overlaps it.
  std::vector<FaceKey>
  brute_force(const mesh::TetMesh &mesh, const std::vector<double> &x, const Box &box)
  {
    std::vector<FaceKey> keys;
    for (const auto &bf : mesh.get_boundary_faces())
    {
      Box              b;
      const mesh::Tet &t = mesh.tet(bf.tet);
      for (const unsigned int k : mesh::TetMesh::face_vertices[bf.face])
        b.extend(cut::Point{{x[3 * t[k]], x[3 * t[k] + 1], x[3 * t[k] + 2]}});
      if (b.overlaps(box))
        keys.emplace_back(bf.tet, bf.face);
    }
    std::sort(keys.begin(), keys.end());
    return keys;
  }

  std::vector<FaceKey>
  tree_answer(const BoundaryFaceTree    &tree,
              const mesh::TetMesh       &mesh,
              const std::vector<double> &x,
              const Box                 &box)
  {
    std::vector<BoundaryFaceTree::Face> hits;
    tree.query(mesh, x.data(), box, hits);
    std::vector<FaceKey> keys;
    for (const auto &f : hits)
      keys.emplace_back(f.tet, f.face);
    std::sort(keys.begin(), keys.end());
    return keys;
  }

  /// Small random boxes around the deformed object, each compared with a search of
  /// every face; returns how many answers were not empty.
  unsigned int
  expect_same_answers(const BoundaryFaceTree    &tree,
                      const mesh::TetMesh       &mesh,
                      const std::vector<double> &x,
                      std::mt19937              &rng,
                      const std::string         &where)
  {
    Box all;
    for (std::size_t i = 0; i < x.size(); i += 3)
      all.extend(cut::Point{{x[i], x[i + 1], x[i + 2]}});
    std::uniform_real_distribution<double> u(0, 1), size(0, 0.15);
    unsigned int                           non_empty = 0;
    for (unsigned int q = 0; q < 200; ++q)
    {
      Box box;
      for (unsigned int d = 0; d < 3; ++d)
      {
        const double extent = all.upper[d] - all.lower[d];
        box.lower[d]        = all.lower[d] - 0.1 * extent + 1.2 * extent * u(rng);
        box.upper[d]        = box.lower[d] + extent * size(rng);
      }
      const auto expected = brute_force(mesh, x, box);
      EXPECT_EQ(tree_answer(tree, mesh, x, box), expected) << where << ", query " << q;
      non_empty += !expected.empty();
    }
    return non_empty;
  }
} // namespace


TEST(CutBoundaryFaceTree, AnswersLikeASearchOfEveryFaceAsTheTissueDeforms)
{
  std::mt19937        rng(3);
  const mesh::TetMesh mesh = box_tet_mesh(6, rng);
  std::vector<double> x(3 * mesh.n_vertices());
  for (unsigned int v = 0; v < mesh.n_vertices(); ++v)
    for (unsigned int d = 0; d < 3; ++d)
      x[3 * v + d] = mesh.vertex(v)[d];
  BoundaryFaceTree tree;
  tree.build(mesh, x.data());
  ASSERT_EQ(tree.size(), mesh.get_boundary_faces().size());
  // A quarter of the median face size (faces of 1/6 by 1/6).
  EXPECT_NEAR(tree.margin(), 0.25 / 6, 1e-12);
  EXPECT_GT(expect_same_answers(tree, mesh, x, rng, "at rest"), 20u);

  // Small jitters: each within the margin, together far beyond it. The boxes are
  // refitted only when some vertex has drifted past the margin since the last fit.
  std::normal_distribution<double> jitter(0, 0.002);
  unsigned int                     refits = 0, kept = 0;
  for (unsigned int step = 0; step < 60; ++step)
  {
    for (double &c : x)
      c += jitter(rng) + 0.001; // a drift along (1, 1, 1) as well
    const bool refitted = tree.refit(mesh, x.data());
    refits += refitted;
    kept += !refitted;
    expect_same_answers(tree, mesh, x, rng, "jitter step " + std::to_string(step));
    ASSERT_FALSE(::testing::Test::HasFailure());
  }
  EXPECT_GT(refits, 0u);
  EXPECT_GT(kept, refits);

  // A large deformation at once (a twist about z and a stretch along x): refitted.
  for (std::size_t i = 0; i < x.size(); i += 3)
  {
    const double angle = 0.8 * x[i + 2], c = std::cos(angle), s = std::sin(angle);
    const double px = 1.7 * x[i], py = x[i + 1];
    x[i]     = c * px - s * py;
    x[i + 1] = s * px + c * py;
  }
  EXPECT_TRUE(tree.refit(mesh, x.data()));
  EXPECT_GT(expect_same_answers(tree, mesh, x, rng, "twisted"), 20u);
  // Unchanged positions need no refit.
  EXPECT_FALSE(tree.refit(mesh, x.data()));
}


namespace
{
  /**
   * Splits the boundary face (tet, face) of @p mesh at its centroid, as a cut replaces
   * boundary faces by smaller ones: the cell becomes three cells, the face three
   * boundary faces, which are given to @p tree; @p x gets the new vertex at the
   * centroid of the face at @p x.
   */
  void
  split_boundary_face(mesh::TetMesh       &mesh,
                      std::vector<double> &x,
                      BoundaryFaceTree    &tree,
                      const unsigned int   tet,
                      const unsigned int   face)
  {
    const mesh::Tet                    old   = mesh.tet(tet);
    const std::array<unsigned int, 3> &local = mesh::TetMesh::face_vertices[face];
    mesh::Point3                       centre;
    std::array<double, 3>              deformed{};
    for (const unsigned int k : local)
      for (unsigned int d = 0; d < 3; ++d)
      {
        centre[d] += mesh.vertex(old[k])[d] / 3;
        deformed[d] += x[3 * old[k] + d] / 3;
      }
    const unsigned int p = mesh.add_vertex(centre);
    x.insert(x.end(), deformed.begin(), deformed.end());
    std::vector<mesh::Tet> children;
    for (const unsigned int k : local)
    {
      mesh::Tet child = old;
      child[k]        = p;
      children.push_back(child);
    }
    std::vector<std::array<unsigned int, 4>> ids(children.size(), {{0, 0, 0, 0}});
    std::vector<unsigned int>                added;
    mesh::TetMesh::Update                    update;
    mesh.replace_tets({tet}, children, ids, added, update);
    for (const unsigned int c : added)
      for (unsigned int f = 0; f < 4; ++f)
        if (mesh.neighbor(c, f) == mesh::invalid_index)
          tree.add_face(mesh, c, f);
  }
} // namespace


TEST(CutBoundaryFaceTree, FacesAddedByCutsAreFoundAndMergedLogarithmically)
{
  std::mt19937  rng(5);
  mesh::TetMesh mesh = box_tet_mesh(4, rng);
  mesh.enable_local_updates();
  std::vector<double> x(3 * mesh.n_vertices());
  for (unsigned int v = 0; v < mesh.n_vertices(); ++v)
    for (unsigned int d = 0; d < 3; ++d)
      x[3 * v + d] = mesh.vertex(v)[d] * (1 + 0.1 * d);
  BoundaryFaceTree tree;
  tree.build(mesh, x.data());
  const std::size_t initial = tree.size();
  ASSERT_EQ(initial, mesh.get_boundary_faces().size());

  // Boundary faces split one at a time, the tissue drifting meanwhile; every few
  // splits the tree is refitted (as the cutter does before each blade motion) and its
  // answers checked against a search of every face. The pending list becomes trees of
  // the logarithmic method; past the mesh's own boundary in added faces the whole tree
  // is rebuilt (its size then counts the live faces only).
  unsigned int most_trees = 0, rebuilds = 0;
  std::size_t  last_size = tree.size();
  for (unsigned int split = 1; split <= 400; ++split)
  {
    const auto &faces = mesh.get_boundary_faces();
    const auto  bf =
      faces[std::uniform_int_distribution<std::size_t>(0, faces.size() - 1)(rng)];
    split_boundary_face(mesh, x, tree, bf.tet, bf.face);
    if (split % 10 != 0)
      continue;
    for (double &c : x)
      c += 0.004;
    tree.refit(mesh, x.data());
    most_trees = std::max(most_trees, tree.n_added_trees());
    rebuilds += tree.size() < last_size;
    last_size = tree.size();
    expect_same_answers(tree, mesh, x, rng, "after split " + std::to_string(split));
    ASSERT_FALSE(::testing::Test::HasFailure());
  }
  EXPECT_EQ(mesh.get_boundary_faces().size(), initial + 2 * 400);
  EXPECT_GE(most_trees, 2u);
  EXPECT_GE(rebuilds, 1u);
}


namespace
{
  /// A random point in [lo, hi]³.
  cut::Point
  random_point(std::mt19937 &rng, const double lo, const double hi)
  {
    std::uniform_real_distribution<double> u(lo, hi);
    return {{u(rng), u(rng), u(rng)}};
  }

  /// Whether triangle @p t meets box @p b, by its pieces: a vertex inside, a box edge
  /// through the triangle, or a triangle edge through a face of the box.
  bool
  triangle_meets_box(const std::array<cut::Point, 3> &t, const Box &b)
  {
    const auto inside = [&](const cut::Point &p)
    {
      for (unsigned int d = 0; d < 3; ++d)
        if (p[d] < b.lower[d] || p[d] > b.upper[d])
          return false;
      return true;
    };
    for (const cut::Point &p : t)
      if (inside(p))
        return true;
    std::array<cut::Point, 8> corner;
    for (unsigned int c = 0; c < 8; ++c)
      for (unsigned int d = 0; d < 3; ++d)
        corner[c][d] = (c >> d) & 1 ? b.upper[d] : b.lower[d];
    double s = 0;
    for (unsigned int c = 0; c < 8; ++c)
      for (unsigned int d = 0; d < 3; ++d)
        if (!((c >> d) & 1)
            && cut::segment_hits_triangle(
              corner[c], corner[c | (1u << d)], t[0], t[1], t[2], s))
          return true;
    // The box's faces as two triangles each: corners with bit d fixed.
    for (unsigned int d = 0; d < 3; ++d)
      for (unsigned int side = 0; side < 2; ++side)
      {
        const unsigned int e = (d + 1) % 3, f = (d + 2) % 3, base = side << d;
        const cut::Point  &p00 = corner[base], &p10 = corner[base | (1u << e)],
                         &p01 = corner[base | (1u << f)],
                         &p11 = corner[base | (1u << e) | (1u << f)];
        for (unsigned int k = 0; k < 3; ++k)
          if (cut::segment_hits_triangle(t[k], t[(k + 1) % 3], p00, p10, p11, s)
              || cut::segment_hits_triangle(t[k], t[(k + 1) % 3], p00, p11, p01, s))
            return true;
      }
    return false;
  }
} // namespace


TEST(CutBoundaryFaceTree, BoxMeetsEveryTriangleThatTouchesIt)
{
  // Boxes and triangles of every proportion around the unit cube: meets() never
  // separates a triangle that meets the box, and separates most of those that do not.
  std::mt19937 rng(11);
  unsigned int met = 0, apart = 0, separated = 0;
  for (unsigned int trial = 0; trial < 20000; ++trial)
  {
    Box b;
    b.extend(random_point(rng, 0, 1));
    b.extend(random_point(rng, 0, 1));
    const double              spread = trial % 2 ? 1.5 : 0.3;
    const cut::Point          centre = random_point(rng, 0, 1);
    std::array<cut::Point, 3> t;
    for (cut::Point &p : t)
      p = cut::add(centre, random_point(rng, -spread, spread));
    const bool meets = triangle_meets_box(t, b);
    met += meets;
    apart += !meets;
    if (meets)
      EXPECT_TRUE(b.meets(t)) << "trial " << trial;
    else
      separated += !b.meets(t);
  }
  EXPECT_GT(met, 2000u);
  EXPECT_GT(apart, 2000u);
  EXPECT_GT(separated, 0.95 * apart);
}


TEST(CutBoundaryFaceTree, SweptTriangleQueriesKeepEveryFaceTheyMeet)
{
  // Thin, slanted swept surfaces (as a long blade moving a little) on a deformed box:
  // the faces whose triangle meets a swept triangle are all in the triangle query's
  // answer, which is part of the box query's answer and far smaller than it.
  std::mt19937        rng(13);
  const mesh::TetMesh mesh = box_tet_mesh(8, rng);
  std::vector<double> x(3 * mesh.n_vertices());
  for (unsigned int v = 0; v < mesh.n_vertices(); ++v)
  {
    const mesh::Point3 &r = mesh.vertex(v);
    x[3 * v]              = r[0] + 0.1 * r[1] * r[2];
    x[3 * v + 1]          = r[1];
    x[3 * v + 2]          = r[2] + 0.05 * r[0];
  }
  BoundaryFaceTree tree;
  tree.build(mesh, x.data());
  std::size_t by_triangles = 0, by_box = 0;
  for (unsigned int q = 0; q < 300; ++q)
  {
    const cut::Point tail = random_point(rng, -0.3, 1.3),
                     head = random_point(rng, -0.3, 1.3);
    const cut::Point step = cut::scale(0.02, random_point(rng, -1, 1));
    const std::array<std::array<cut::Point, 3>, 2> swept = {
      {{{tail, head, cut::add(tail, step)}},
       {{cut::add(tail, step), head, cut::add(head, step)}}}};
    std::vector<BoundaryFaceTree::Face> slim, wide;
    tree.query(mesh, x.data(), swept, slim);
    Box box = Box::around(swept[0]);
    box.extend(Box::around(swept[1]));
    tree.query(mesh, x.data(), box, wide);
    by_triangles += slim.size();
    by_box += wide.size();
    std::set<FaceKey> in_slim, in_wide;
    for (const auto &f : slim)
      in_slim.emplace(f.tet, f.face);
    for (const auto &f : wide)
      in_wide.emplace(f.tet, f.face);
    for (const FaceKey &k : in_slim)
      EXPECT_TRUE(in_wide.count(k)) << "query " << q;
    for (const auto &bf : mesh.get_boundary_faces())
    {
      const BoundaryFaceTree::Face f = {
        bf.tet,
        bf.face,
        {{mesh.tet(bf.tet)[mesh::TetMesh::face_vertices[bf.face][0]],
          mesh.tet(bf.tet)[mesh::TetMesh::face_vertices[bf.face][1]],
          mesh.tet(bf.tet)[mesh::TetMesh::face_vertices[bf.face][2]]}}};
      const auto triangle = BoundaryFaceTree::triangle(f, x.data());
      if (cut::triangles_intersect(triangle, swept[0])
          || cut::triangles_intersect(triangle, swept[1]))
      {
        EXPECT_TRUE(in_slim.count({bf.tet, bf.face})) << "query " << q;
      }
    }
    ASSERT_FALSE(::testing::Test::HasFailure());
  }
  EXPECT_LT(3 * by_triangles, by_box);
}
