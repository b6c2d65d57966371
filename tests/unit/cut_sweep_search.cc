// FindTetraToCut on its own (cut/sweep_search.h): first contact from outside, the
// propagation through crossed edges, the cells the blade is in, and the search after
// a local mesh update.
#include <lacerta/cut/sweep_search.h>
#include <lacerta/mesh/tet_mesh.h>
#include <lacerta/physics/particle_system.h>

#include <gtest/gtest.h>

#include "cut_split_support.h"
#include "physics_test_support.h"
#include <algorithm>
#include <memory>
#include <random>
#include <set>

namespace
{
  using namespace lacerta;
  using cut::Blade;
  using cut::Point;
  using cut::SweptTriangles;

  /// The triangles a blade sweeps from @p from to @p to.
  SweptTriangles
  swept(const Blade &from, const Blade &to)
  {
    return {{{{from.tail, from.head, to.tail}}, {{to.tail, from.head, to.head}}}};
  }

  /// A vertical blade at (x, y) through z from -0.5 to 1.5.
  Blade
  vertical(const double x, const double y)
  {
    return {{{x, y, 1.5}}, {{x, y, -0.5}}};
  }

  /// The unit box of n^3 cubes (six tetrahedra each), with its particles at rest.
  struct Box
  {
    mesh::TetMesh                            mesh;
    std::unique_ptr<physics::ParticleSystem> system;

    explicit Box(const unsigned int n)
    {
      std::mt19937 rng(3);
      mesh = cut::test_support::box_tet_mesh(n, rng);
      mesh.enable_local_updates();
      system = test_support::make_system(mesh, 1000.0, 1e4);
    }

    /// Every cell that the swept triangles meet, by testing them all.
    std::set<unsigned int>
    cells_meeting(const cut::SweepSearch &search, const SweptTriangles &s) const
    {
      std::set<unsigned int> cells;
      for (unsigned int t = 0; t < mesh.n_tets(); ++t)
        if (search.tet_meets(t, s))
          cells.insert(t);
      return cells;
    }
  };
} // namespace


TEST(CutSweepSearch, FirstContactFromOutsideFindsEveryCellTheSweepMeets)
{
  Box              box(4);
  cut::SweepSearch search(box.mesh, *box.system);
  const Blade      from = vertical(-0.2, 0.3), to = vertical(0.3, 0.3);
  const auto       s = swept(from, to);
  search.find(s, to);
  const std::set<unsigned int> found(search.cells().begin(), search.cells().end());
  EXPECT_EQ(found.size(), search.cells().size()); // each cell once
  EXPECT_EQ(found, box.cells_meeting(search, s));
  EXPECT_FALSE(found.empty());
  // The blade ends inside: the active cells are those it is in, all among them.
  ASSERT_FALSE(search.active().empty());
  for (const unsigned int t : search.active())
  {
    EXPECT_TRUE(search.blade_in_tet(t, to));
    EXPECT_TRUE(found.count(t));
  }
  for (unsigned int t = 0; t < box.mesh.n_tets(); ++t)
    if (search.blade_in_tet(t, to))
      EXPECT_TRUE(std::count(search.active().begin(), search.active().end(), t));
}


TEST(CutSweepSearch, ASweepInsideTheTissueStartsFromTheActiveCells)
{
  Box              box(4);
  cut::SweepSearch search(box.mesh, *box.system);
  const Blade a = vertical(-0.2, 0.3), b = vertical(0.3, 0.3), c = vertical(0.55, 0.4);
  search.find(swept(a, b), b);
  // The second sweep starts inside, from the cells the blade is in.
  const auto s = swept(b, c);
  search.find(s, c);
  const std::set<unsigned int> found(search.cells().begin(), search.cells().end());
  EXPECT_EQ(found, box.cells_meeting(search, s));
}


TEST(CutSweepSearch, ABladeOutsideTheTissueMeetsNothing)
{
  Box              box(2);
  cut::SweepSearch search(box.mesh, *box.system);
  const Blade      from = vertical(-0.5, 0.3), to = vertical(-0.2, 0.6);
  search.find(swept(from, to), to);
  EXPECT_TRUE(search.cells().empty());
  EXPECT_TRUE(search.active().empty());
  EXPECT_FALSE(search.blade_in_tet(0, to));
}


TEST(CutSweepSearch, TheSearchFollowsALocalReplacementOfCells)
{
  Box              box(3);
  cut::SweepSearch search(box.mesh, *box.system);
  const Blade      from = vertical(-0.2, 0.5), to = vertical(0.5, 0.5);
  search.find(swept(from, to), to);
  ASSERT_FALSE(search.active().empty());
  // Replace the first active cell by four children around its centroid (a local
  // update that creates no boundary face) and let the search follow.
  const unsigned int t   = search.active().front();
  const mesh::Tet    old = box.mesh.tet(t);
  mesh::Point3       centre{{0, 0, 0}};
  for (const unsigned int v : old)
    for (unsigned int d = 0; d < 3; ++d)
      centre[d] += 0.25 * box.mesh.vertex(v)[d];
  const unsigned int c = box.mesh.add_vertex(centre);
  box.system->add_particle(centre, centre, {{0, 0, 0}});
  std::vector<mesh::Tet> children;
  for (unsigned int k = 0; k < 4; ++k)
  {
    mesh::Tet child = old;
    child[k]        = c;
    children.push_back(child);
  }
  const std::vector<unsigned int> removed = {t};
  std::vector<unsigned int>       added;
  mesh::TetMesh::Update           update;
  box.mesh.replace_tets(removed,
                        children,
                        std::vector<std::array<unsigned int, 4>>(4, {{0, 0, 0, 0}}),
                        added,
                        update);
  search.follow_replacement(removed, added, to);
  for (const unsigned int a : search.active())
    EXPECT_TRUE(search.blade_in_tet(a, to));
  // The blade is in one of the children (it was in their parent).
  EXPECT_TRUE(
    std::any_of(added.begin(),
                added.end(),
                [&](const unsigned int a) {
                  return std::count(search.active().begin(), search.active().end(), a);
                }));
}
