// VertexStars: the same stars, in the same order, as a vector per vertex, in place and
// in overflow.

#include <lacerta/base/exceptions.h>
#include <lacerta/mesh/vertex_stars.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <vector>

using namespace lacerta;
using namespace lacerta::mesh;

namespace
{
  /// Expects star @p v of @p stars to hold exactly @p expected, in order.
  void
  expect_star(const VertexStars               &stars,
              const unsigned int               v,
              const std::vector<unsigned int> &expected)
  {
    const VertexStars::Star star = stars[v];
    ASSERT_EQ(star.size(), expected.size()) << "vertex " << v;
    ASSERT_EQ(stars.star_size(v), expected.size()) << "vertex " << v;
    EXPECT_EQ(star.empty(), expected.empty());
    EXPECT_TRUE(std::equal(star.begin(), star.end(), expected.begin())) << "vertex " << v;
    for (std::size_t i = 0; i < expected.size(); ++i)
      EXPECT_EQ(star[i], expected[i]);
  }
} // namespace


TEST(VertexStars, InsertionAppendsAndErasureKeepsTheOrder)
{
  VertexStars stars;
  EXPECT_TRUE(stars.empty());
  stars.resize(3);
  EXPECT_EQ(stars.size(), 3u);
  for (const unsigned int t : {7u, 3u, 9u, 1u, 5u})
    stars.insert(1, t);
  stars.insert(2, 4);
  expect_star(stars, 0, {});
  expect_star(stars, 1, {7, 3, 9, 1, 5});
  expect_star(stars, 2, {4});
  EXPECT_EQ(stars[1].front(), 7u);
  stars.erase(1, 9);
  expect_star(stars, 1, {7, 3, 1, 5});
  stars.erase(1, 7);
  stars.insert(1, 9);
  expect_star(stars, 1, {3, 1, 5, 9});
  stars.erase(1, 9);
  expect_star(stars, 1, {3, 1, 5});
  expect_star(stars, 2, {4});
  EXPECT_THROW(stars.erase(1, 8), Error);
  expect_star(stars, 1, {3, 1, 5});
}


TEST(VertexStars, LargeStarsOverflowAndComeBackInOrder)
{
  // One line per vertex: 15 cells in place.
  VertexStars stars(16);
  ASSERT_EQ(stars.inline_capacity(), 15u);
  stars.resize(2);
  std::vector<unsigned int> expected;
  for (unsigned int t = 0; t < 40; ++t)
  {
    stars.insert(0, 100 + t);
    expected.push_back(100 + t);
    stars.insert(1, t);
    expect_star(stars, 0, expected);
  }
  // Erase across the boundary between overflow and in place, from the middle and
  // from both ends.
  while (!expected.empty())
  {
    const std::size_t i = expected.size() % 3 == 0   ? 0
                          : expected.size() % 3 == 1 ? expected.size() - 1
                                                     : expected.size() / 2;
    stars.erase(0, expected[i]);
    expected.erase(expected.begin() + i);
    expect_star(stars, 0, expected);
  }
  // Grows again (the overflow list is reused) without touching the other star.
  for (unsigned int t = 0; t < 20; ++t)
  {
    stars.insert(0, t);
    expected.push_back(t);
  }
  expect_star(stars, 0, expected);
  std::vector<unsigned int> other(40);
  for (unsigned int t = 0; t < 40; ++t)
    other[t] = t;
  expect_star(stars, 1, other);
}


TEST(VertexStars, GrowthKeepsTheStarsAndAddsEmptyOnes)
{
  VertexStars stars(32);
  stars.reserve(4);
  stars.resize(2);
  for (unsigned int t = 0; t < 50; ++t)
    stars.insert(t % 2, t);
  // Past the reserve: the lines are copied, overflow lists stay where they are.
  stars.resize(1000);
  std::vector<unsigned int> even, odd;
  for (unsigned int t = 0; t < 50; ++t)
    (t % 2 ? odd : even).push_back(t);
  expect_star(stars, 0, even);
  expect_star(stars, 1, odd);
  for (unsigned int v = 2; v < 1000; ++v)
    expect_star(stars, v, {});
  // Shrinking frees the dropped vertices' overflow; a vertex added again is empty.
  stars.resize(1);
  stars.resize(2);
  expect_star(stars, 0, even);
  expect_star(stars, 1, {});
  stars.clear();
  EXPECT_TRUE(stars.empty());
}


TEST(VertexStars, MatchesAVectorPerVertexUnderRandomUpdates)
{
  std::mt19937 random(5);
  for (const unsigned int slot_words : {16u, 48u})
  {
    VertexStars                            stars(slot_words);
    std::vector<std::vector<unsigned int>> reference(30);
    stars.resize(30);
    unsigned int next = 0;
    for (unsigned int step = 0; step < 20000; ++step)
    {
      const unsigned int v = random() % reference.size();
      auto              &r = reference[v];
      // More insertions than erasures while small, the reverse when large, so that
      // stars cross the in-place limit in both directions many times.
      const bool grow = r.empty() || random() % 80 >= r.size();
      if (grow)
      {
        stars.insert(v, next);
        r.push_back(next++);
      }
      else
      {
        const std::size_t i = random() % r.size();
        stars.erase(v, r[i]);
        r.erase(r.begin() + i);
      }
      if (step % 97 == 0)
      {
        reference.emplace_back();
        stars.resize(reference.size());
      }
    }
    for (unsigned int v = 0; v < reference.size(); ++v)
      expect_star(stars, v, reference[v]);
  }
}


TEST(VertexStars, ErasingMarkedCellsAtOnceGivesTheStarOfErasingThemOneByOne)
{
  // Stars of every size around the in-place limit of 15 cells (slot of 16 words),
  // with random subsets marked: in place, overflowing and staying so, and
  // overflowing and coming back in place.
  std::mt19937 random(11);
  for (unsigned int trial = 0; trial < 400; ++trial)
  {
    VertexStars               at_once(16), one_by_one(16);
    const unsigned int        n = random() % 40;
    std::vector<unsigned int> cells, kept;
    at_once.resize(2);
    one_by_one.resize(2);
    for (unsigned int i = 0; i < n; ++i)
    {
      const unsigned int t = random() % 1000;
      if (std::find(cells.begin(), cells.end(), t) != cells.end())
        continue;
      cells.push_back(t);
      at_once.insert(1, t);
      one_by_one.insert(1, t);
      at_once.insert(0, t); // a neighbouring star that must stay as it is
    }
    std::vector<bool> marked(1000, false);
    for (const unsigned int t : cells)
      marked[t] = random() % 3 == 0;
    for (const unsigned int t : cells)
      if (marked[t])
        one_by_one.erase(1, t);
      else
        kept.push_back(t);
    at_once.erase_marked(1, [&](const unsigned int t) { return marked[t]; });
    expect_star(at_once, 1, kept);
    expect_star(one_by_one, 1, kept);
    expect_star(at_once, 0, cells);
    // The star still grows and shrinks as any other.
    at_once.insert(1, 1000);
    kept.push_back(1000);
    expect_star(at_once, 1, kept);
  }
}


TEST(VertexStars, RefusesASlotThatIsNotWholeCacheLines)
{
  EXPECT_THROW(VertexStars(0), Error);
  EXPECT_THROW(VertexStars(24), Error);
}
