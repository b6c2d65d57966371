/**
 * @file
 * 3x3 matrices of the force models per tetrahedron (deformation gradients, stresses),
 * stored row-major in a flat array, with the few operations they need.
 */
#pragma once

#include <array>

namespace lacerta::physics
{
  /// A 3x3 matrix, row-major: entry (r, s) is element 3 r + s.
  using Matrix3 = std::array<double, 9>;

  /// The determinant of @p a.
  inline double
  determinant(const Matrix3 &a)
  {
    return a[0] * (a[4] * a[8] - a[5] * a[7]) - a[1] * (a[3] * a[8] - a[5] * a[6])
           + a[2] * (a[3] * a[7] - a[4] * a[6]);
  }

  /// The transpose of the inverse of @p a, whose determinant is @p det (non-zero).
  inline Matrix3
  inverse_transpose(const Matrix3 &a, const double det)
  {
    const double inv = 1.0 / det;
    return {{(a[4] * a[8] - a[5] * a[7]) * inv,
             (a[5] * a[6] - a[3] * a[8]) * inv,
             (a[3] * a[7] - a[4] * a[6]) * inv,
             (a[2] * a[7] - a[1] * a[8]) * inv,
             (a[0] * a[8] - a[2] * a[6]) * inv,
             (a[1] * a[6] - a[0] * a[7]) * inv,
             (a[1] * a[5] - a[2] * a[4]) * inv,
             (a[2] * a[3] - a[0] * a[5]) * inv,
             (a[0] * a[4] - a[1] * a[3]) * inv}};
  }

  /// The squared Frobenius norm of @p a.
  inline double
  squared_norm(const Matrix3 &a)
  {
    double sum = 0;
    for (const double x : a)
      sum += x * x;
    return sum;
  }
} // namespace lacerta::physics
