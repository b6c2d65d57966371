/**
 * @file
 * Intersection predicates, barycentric coordinates and boxes on plain points, shared by
 * the cutter, the bounding-volume tree and the tests. Plain C++17, inline: the cutter's
 * inner loops call them per edge. The vector algebra they use is mesh/point.h's,
 * brought into lacerta::cut below.
 */
#pragma once

#include <lacerta/cut/tet_decomposition.h>
#include <lacerta/mesh/point.h>

#include <algorithm>
#include <array>
#include <cmath>

namespace lacerta::cut
{
  // The vector algebra of cut::Point (= mesh::Point3), for unqualified and cut::
  // qualified calls.
  using mesh::add;
  using mesh::cross;
  using mesh::dot;
  using mesh::lerp;
  using mesh::norm;
  using mesh::normalized;
  using mesh::scale;
  using mesh::sub;

  /// Signed volume of the tetrahedron (a, b, c, d).
  inline double
  volume(const Point &a, const Point &b, const Point &c, const Point &d)
  {
    return signed_volume6(a, b, c, d) / 6.0;
  }

  /**
   * Whether the segment [p, q] meets the triangle (a, b, c), boundaries included; on a
   * hit @p t is the parameter along the segment. Möller-Trumbore; a segment lying in
   * the triangle's plane counts as no hit (the cutter treats it through the plane
   * sides instead). A positive @p tolerance widens the barycentric and segment ranges
   * by that much, so that a segment through an edge shared by two triangles is found
   * by one of them despite rounding.
   */
  inline bool
  segment_hits_triangle(const Point &p,
                        const Point &q,
                        const Point &a,
                        const Point &b,
                        const Point &c,
                        double      &t,
                        const double tolerance = 0)
  {
    const Point  d   = sub(q, p);
    const Point  e1  = sub(b, a);
    const Point  e2  = sub(c, a);
    const Point  h   = cross(d, e2);
    const double det = dot(e1, h);
    const double tol = 1e-14 * norm(d) * norm(e1) * norm(e2);
    if (std::abs(det) <= tol)
      return false;
    const Point  s = sub(p, a);
    const double u = dot(s, h) / det;
    if (u < -tolerance || u > 1 + tolerance)
      return false;
    const Point  r = cross(s, e1);
    const double v = dot(d, r) / det;
    if (v < -tolerance || u + v > 1 + tolerance)
      return false;
    t = dot(e2, r) / det;
    return t >= -tolerance && t <= 1 + tolerance;
  }

  /// Whether two triangles intersect (an edge of one crosses the other).
  inline bool
  triangles_intersect(const std::array<Point, 3> &x, const std::array<Point, 3> &y)
  {
    double t;
    for (unsigned int i = 0; i < 3; ++i)
      if (segment_hits_triangle(x[i], x[(i + 1) % 3], y[0], y[1], y[2], t)
          || segment_hits_triangle(y[i], y[(i + 1) % 3], x[0], x[1], x[2], t))
        return true;
    return false;
  }

  /**
   * Barycentric coordinates of @p x in the tetrahedron (a, b, c, d); they sum to one.
   */
  inline std::array<double, 4>
  barycentric(const Point &a,
              const Point &b,
              const Point &c,
              const Point &d,
              const Point &x)
  {
    const double v  = signed_volume6(a, b, c, d);
    const double l1 = signed_volume6(a, x, c, d) / v;
    const double l2 = signed_volume6(a, b, x, d) / v;
    const double l3 = signed_volume6(a, b, c, x) / v;
    return {{1.0 - l1 - l2 - l3, l1, l2, l3}};
  }

  /// An axis-aligned box.
  struct Box
  {
    Point lower{{1e300, 1e300, 1e300}};
    Point upper{{-1e300, -1e300, -1e300}};

    /// Grows the box to contain @p p.
    void
    extend(const Point &p)
    {
      for (unsigned int d = 0; d < 3; ++d)
      {
        lower[d] = std::min(lower[d], p[d]);
        upper[d] = std::max(upper[d], p[d]);
      }
    }

    /// Grows the box to contain @p b.
    void
    extend(const Box &b)
    {
      extend(b.lower);
      extend(b.upper);
    }

    /// Grows the box by @p margin on every side.
    void
    inflate(const double margin)
    {
      for (unsigned int d = 0; d < 3; ++d)
      {
        lower[d] -= margin;
        upper[d] += margin;
      }
    }

    /// The largest extent of the box along an axis.
    double
    size() const
    {
      return std::max({upper[0] - lower[0], upper[1] - lower[1], upper[2] - lower[2]});
    }

    /// The box around the @p n points @p p.
    template <std::size_t n>
    static Box
    around(const std::array<Point, n> &p)
    {
      Box box;
      for (const Point &q : p)
        box.extend(q);
      return box;
    }

    /// Whether the boxes overlap.
    bool
    overlaps(const Box &b) const
    {
      for (unsigned int d = 0; d < 3; ++d)
        if (lower[d] > b.upper[d] || b.lower[d] > upper[d])
          return false;
      return true;
    }

    /**
     * Whether triangle @p t may meet the box: false only if an axis separates them
     * (the box's three axes, the triangle's normal, and the nine products of their
     * edges; Akenine-Möller's test). The box is taken larger by 1e-9 of its size, so
     * that rounding never separates a triangle that touches it.
     */
    bool
    meets(const std::array<Point, 3> &t) const
    {
      Point centre, half;
      for (unsigned int d = 0; d < 3; ++d)
      {
        centre[d] = 0.5 * (lower[d] + upper[d]);
        half[d]   = 0.5 * (upper[d] - lower[d]);
      }
      const double slack = 1e-9 * std::max({half[0], half[1], half[2], 1e-300});
      for (double &h : half)
        h += slack;
      const std::array<Point, 3> v = {
        {sub(t[0], centre), sub(t[1], centre), sub(t[2], centre)}};
      // Does the axis a separate the triangle (its vertices' projections) from the
      // box (the projections within ± h·|a|)?
      const auto separates = [&](const Point &a)
      {
        const double p0 = dot(a, v[0]), p1 = dot(a, v[1]), p2 = dot(a, v[2]);
        const double r =
          half[0] * std::abs(a[0]) + half[1] * std::abs(a[1]) + half[2] * std::abs(a[2]);
        return std::min({p0, p1, p2}) > r || std::max({p0, p1, p2}) < -r;
      };
      const std::array<Point, 3> axes = {{{{1, 0, 0}}, {{0, 1, 0}}, {{0, 0, 1}}}};
      for (const Point &axis : axes)
        if (separates(axis))
          return false;
      const std::array<Point, 3> edges = {
        {sub(v[1], v[0]), sub(v[2], v[1]), sub(v[0], v[2])}};
      if (separates(cross(edges[0], edges[1])))
        return false;
      for (const Point &e : edges)
        for (const Point &axis : axes)
          if (separates(cross(axis, e)))
            return false;
      return true;
    }
  };
} // namespace lacerta::cut
