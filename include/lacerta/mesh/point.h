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
} // namespace lacerta::mesh
