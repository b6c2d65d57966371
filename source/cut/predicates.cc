#include <lacerta/cut/predicates.h>

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>

namespace lacerta::cut
{
  namespace
  {
    using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;

    Kernel::Point_3
    to_cgal(const mesh::Point3 &p)
    {
      return {p[0], p[1], p[2]};
    }
  } // namespace


  int
  orientation(const mesh::Point3 &a,
              const mesh::Point3 &b,
              const mesh::Point3 &c,
              const mesh::Point3 &d)
  {
    // CGAL's orientation(p, q, r, s) is POSITIVE when s lies on the positive side of
    // (p, q, r), i.e. when the determinant [q - p, r - p, s - p] is positive.
    return static_cast<int>(
      CGAL::orientation(to_cgal(a), to_cgal(b), to_cgal(c), to_cgal(d)));
  }


  bool
  line_meets_triangle(const mesh::Point3 &p,
                      const mesh::Point3 &q,
                      const mesh::Point3 &a,
                      const mesh::Point3 &b,
                      const mesh::Point3 &c)
  {
    // The line meets the closed triangle iff the orientations of (p, q) with the
    // triangle's three edges do not have opposite signs (all zero: the line lies in
    // the plane, or the triangle is degenerate).
    const int o0 = orientation(p, q, a, b), o1 = orientation(p, q, b, c),
              o2            = orientation(p, q, c, a);
    const bool has_positive = o0 > 0 || o1 > 0 || o2 > 0;
    const bool has_negative = o0 < 0 || o1 < 0 || o2 < 0;
    return has_positive != has_negative;
  }


  int
  segment_crossing(const mesh::Point3 &p,
                   const mesh::Point3 &q,
                   const mesh::Point3 &a,
                   const mesh::Point3 &b,
                   const mesh::Point3 &c)
  {
    const int sp = orientation(a, b, c, p) >= 0 ? 1 : -1;
    const int sq = orientation(a, b, c, q) >= 0 ? 1 : -1;
    if (sp == sq || !line_meets_triangle(p, q, a, b, c))
      return 0;
    return sp;
  }
} // namespace lacerta::cut
