/**
 * @file
 * Exact geometric predicates for the cutter's decisions: the sign of an orientation
 * is computed exactly (CGAL's filtered predicates), so that a decision taken from it
 * (which side of the blade a point lies on, whether an edge crosses a swept triangle)
 * does not depend on rounding.
 */
#pragma once

#include <lacerta/mesh/point.h>

namespace lacerta::cut
{
  /**
   * The exact sign (+1, 0 or -1) of the determinant [b - a, c - a, d - a]: +1 if
   * @p d lies on the side of the plane (a, b, c) that (b - a) x (c - a) points to.
   */
  int
  orientation(const mesh::Point3 &a,
              const mesh::Point3 &b,
              const mesh::Point3 &c,
              const mesh::Point3 &d);

  /**
   * How the segment from @p p to @p q crosses the triangle (a, b, c), decided exactly:
   * 0 if it does not, +1 if it goes from the side (b - a) x (c - a) points to towards
   * the other side, -1 the other way. The triangle is closed (a segment through its
   * boundary crosses it), and an endpoint on its plane counts as lying on the positive
   * side (a consistent tie-break: a point on the blade's plane has a defined side).
   */
  int
  segment_crossing(const mesh::Point3 &p,
                   const mesh::Point3 &q,
                   const mesh::Point3 &a,
                   const mesh::Point3 &b,
                   const mesh::Point3 &c);

  /**
   * Whether the line through @p p and @p q passes through the closed triangle
   * (a, b, c), decided exactly (false for a line in the triangle's plane or a
   * degenerate triangle).
   */
  bool
  line_meets_triangle(const mesh::Point3 &p,
                      const mesh::Point3 &q,
                      const mesh::Point3 &a,
                      const mesh::Point3 &b,
                      const mesh::Point3 &c);
} // namespace lacerta::cut
