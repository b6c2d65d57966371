// The boundary face tree (first contact of the scalpel) on a deforming mesh: its
// answers against a search of every boundary face, and its refits.
#include <lacerta/cut/boundary_face_tree.h>

#include <gtest/gtest.h>

#include "cut_split_support.h"
#include <algorithm>
#include <cmath>
#include <random>
#include <tuple>
#include <vector>

namespace
{
  using namespace lacerta;
  using cut::BoundaryFaceTree;
  using cut::Box;

  /// A face as (tet, face), for comparing sets of answers.
  using FaceKey = std::pair<unsigned int, unsigned int>;

  mesh::TetMesh
  box_tet_mesh(const unsigned int n, std::mt19937 &rng)
  {
    const auto                box = cut::test_support::box_mesh(n, rng);
    std::vector<mesh::Point3> x(box.points.begin(), box.points.end());
    std::vector<mesh::Tet>    t;
    for (const auto &c : box.tets)
      t.push_back({{c[0], c[1], c[2], c[3]}});
    return mesh::TetMesh(x, t, "box");
  }

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
