/**
 * @file
 * The one point type of mesh/, cut/ and mt/, and its small vector algebra. Plain C++17,
 * no deal.II, inline: the cutter's and the builder's inner loops call these per edge.
 */
#pragma once

#include <array>
#include <cmath>

namespace lacerta::mesh
{
  /**
   * A point or vector in 3D, as plain data: the one point type of mesh/, cut/ (as
   * cut::Point) and mt/. The hot loops do not use deal.II types; the functions below
   * are its vector algebra.
   */
  using Point3 = std::array<double, 3>;

  /// a - b.
  inline Point3
  sub(const Point3 &a, const Point3 &b)
  {
    return {a[0] - b[0], a[1] - b[1], a[2] - b[2]};
  }

  /// a + b.
  inline Point3
  add(const Point3 &a, const Point3 &b)
  {
    return {a[0] + b[0], a[1] + b[1], a[2] + b[2]};
  }

  /// s a.
  inline Point3
  scale(const double s, const Point3 &a)
  {
    return {s * a[0], s * a[1], s * a[2]};
  }

  /// a + t (b - a).
  inline Point3
  lerp(const Point3 &a, const Point3 &b, const double t)
  {
    return add(a, scale(t, sub(b, a)));
  }

  /// Scalar product.
  inline double
  dot(const Point3 &a, const Point3 &b)
  {
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
  }

  /// Vector product.
  inline Point3
  cross(const Point3 &a, const Point3 &b)
  {
    return {a[1] * b[2] - a[2] * b[1],
            a[2] * b[0] - a[0] * b[2],
            a[0] * b[1] - a[1] * b[0]};
  }

  /// Euclidean length.
  inline double
  norm(const Point3 &a)
  {
    return std::sqrt(dot(a, a));
  }

  /// Euclidean distance between @p a and @p b.
  inline double
  distance(const Point3 &a, const Point3 &b)
  {
    return norm(sub(a, b));
  }

  /// a / |a|.
  inline Point3
  normalized(const Point3 &a)
  {
    return scale(1.0 / norm(a), a);
  }

  /// Distance from @p p to the triangle (a, b, c), by its closest point (Ericson,
  /// Real-Time Collision Detection, 5.1.5).
  inline double
  point_triangle_distance(const Point3 &p,
                          const Point3 &a,
                          const Point3 &b,
                          const Point3 &c)
  {
    const Point3 ab = sub(b, a), ac = sub(c, a), ap = sub(p, a);
    const double d1 = dot(ab, ap), d2 = dot(ac, ap);
    if (d1 <= 0 && d2 <= 0)
      return distance(p, a);
    const Point3 bp = sub(p, b);
    const double d3 = dot(ab, bp), d4 = dot(ac, bp);
    if (d3 >= 0 && d4 <= d3)
      return distance(p, b);
    const double vc = d1 * d4 - d3 * d2;
    const auto   on = [&](const Point3 &o, const Point3 &e, const double s)
    { return distance(p, add(o, scale(s, e))); };
    if (vc <= 0 && d1 >= 0 && d3 <= 0)
      return on(a, ab, d1 / (d1 - d3));
    const Point3 cp = sub(p, c);
    const double d5 = dot(ab, cp), d6 = dot(ac, cp);
    if (d6 >= 0 && d5 <= d6)
      return distance(p, c);
    const double vb = d5 * d2 - d1 * d6;
    if (vb <= 0 && d2 >= 0 && d6 <= 0)
      return on(a, ac, d2 / (d2 - d6));
    const double va = d3 * d6 - d5 * d4;
    if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0)
      return on(b, sub(c, b), (d4 - d3) / ((d4 - d3) + (d5 - d6)));
    const double denominator = 1 / (va + vb + vc);
    const double v = vb * denominator, w = vc * denominator;
    return distance(p, add(add(a, scale(v, ab)), scale(w, ac)));
  }
} // namespace lacerta::mesh
