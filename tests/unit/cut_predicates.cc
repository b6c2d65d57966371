// The exact predicates the cutter decides crossings with (cut/predicates.h).
#include <lacerta/cut/predicates.h>

#include <gtest/gtest.h>

#include <random>

namespace
{
  using lacerta::cut::line_meets_triangle;
  using lacerta::cut::orientation;
  using lacerta::cut::segment_crossing;
  using lacerta::mesh::Point3;

  /// The floating-point determinant [b - a, c - a, d - a].
  double
  determinant(const Point3 &a, const Point3 &b, const Point3 &c, const Point3 &d)
  {
    const Point3 u{{b[0] - a[0], b[1] - a[1], b[2] - a[2]}};
    const Point3 v{{c[0] - a[0], c[1] - a[1], c[2] - a[2]}};
    const Point3 w{{d[0] - a[0], d[1] - a[1], d[2] - a[2]}};
    return u[0] * (v[1] * w[2] - v[2] * w[1]) - u[1] * (v[0] * w[2] - v[2] * w[0])
           + u[2] * (v[0] * w[1] - v[1] * w[0]);
  }
} // namespace


TEST(CutPredicates, OrientationHasTheSignOfTheDeterminantWhereItIsClear)
{
  std::mt19937                           rng(3);
  std::uniform_real_distribution<double> u(-1, 1);
  const auto random_point = [&] { return Point3{{u(rng), u(rng), u(rng)}}; };
  for (unsigned int k = 0; k < 1000; ++k)
  {
    const Point3 a = random_point(), b = random_point(), c = random_point(),
                 d   = random_point();
    const double det = determinant(a, b, c, d);
    if (std::abs(det) > 1e-9)
    {
      EXPECT_EQ(orientation(a, b, c, d), det > 0 ? 1 : -1);
    }
  }
}


TEST(CutPredicates, OrientationIsExactForPointsOnThePlane)
{
  // d = b + c lies exactly in the plane through 0, b and c whenever the sums are
  // exact; the floating-point determinant is then often a rounding error away from 0,
  // of either sign, and the exact predicate is 0 every time.
  std::mt19937                           rng(5);
  std::uniform_real_distribution<double> u(-1, 1);
  const Point3                           origin{{0, 0, 0}};
  unsigned int                           tested = 0, rounded = 0;
  for (unsigned int k = 0; k < 2000; ++k)
  {
    const Point3 b{{u(rng), u(rng), u(rng)}}, c{{u(rng), u(rng), u(rng)}};
    const Point3 d{{b[0] + c[0], b[1] + c[1], b[2] + c[2]}};
    bool         exact = true;
    for (unsigned int i = 0; i < 3; ++i)
      exact &= d[i] - b[i] == c[i] && d[i] - c[i] == b[i];
    if (!exact)
      continue;
    ++tested;
    rounded += determinant(origin, b, c, d) != 0;
    EXPECT_EQ(orientation(origin, b, c, d), 0);
    // One unit in the last place off the plane along z: a definite side.
    const Point3 above{{d[0], d[1], std::nextafter(d[2], 2.0)}};
    const Point3 below{{d[0], d[1], std::nextafter(d[2], -2.0)}};
    EXPECT_EQ(orientation(origin, b, c, above), -orientation(origin, b, c, below));
  }
  EXPECT_GT(tested, 100u);
  EXPECT_GT(rounded, 0u); // the floating determinant would have judged some of them
}


TEST(CutPredicates, ASegmentThroughASharedEdgeCrossesBothTrianglesTheSameWay)
{
  // The two triangles of a swept quadrilateral share the diagonal (0, 1, 0)-(1, 0, 0)
  // in the plane z = 0; a segment through a point of it crosses both, in one
  // direction, so that the cutter records one crossing.
  const Point3 t0{{0, 0, 0}}, h0{{0, 1, 0}}, t1{{1, 0, 0}}, h1{{1, 1, 0}};
  const Point3 p{{0.5, 0.5, 1}}, q{{0.5, 0.5, -1}};
  const int    first = segment_crossing(p, q, t0, h0, t1);
  const int    other = segment_crossing(p, q, t1, h0, h1);
  EXPECT_NE(first, 0);
  EXPECT_EQ(first, other);
  // Reversed, the other way.
  EXPECT_EQ(segment_crossing(q, p, t0, h0, t1), -first);
  // Missing the triangles: no crossing.
  EXPECT_EQ(segment_crossing(Point3{{2, 2, 1}}, Point3{{2, 2, -1}}, t0, h0, t1), 0);
  // Both ends on one side: no crossing, though the line meets the triangle.
  const Point3 r{{0.2, 0.2, 2}}, s{{0.2, 0.2, 1}};
  EXPECT_EQ(segment_crossing(r, s, t0, h0, t1), 0);
  EXPECT_TRUE(line_meets_triangle(r, s, t0, h0, t1));
}


TEST(CutPredicates, AnEndOnThePlaneCountsAsOnItsPositiveSide)
{
  // The triangle's normal (0, 0, 1): an end on the plane is on the positive side, so a
  // segment from it upwards does not cross and one downwards does.
  const Point3 a{{0, 0, 0}}, b{{1, 0, 0}}, c{{0, 1, 0}};
  const Point3 on{{0.25, 0.25, 0}};
  EXPECT_EQ(segment_crossing(on, Point3{{0.25, 0.25, 1}}, a, b, c), 0);
  EXPECT_EQ(segment_crossing(on, Point3{{0.25, 0.25, -1}}, a, b, c), 1);
  // A degenerate triangle (the blade moving along itself) sweeps nothing.
  const Point3 d{{2, 0, 0}};
  EXPECT_EQ(segment_crossing(Point3{{1, 0, 1}}, Point3{{1, 0, -1}}, a, b, d), 0);
}
