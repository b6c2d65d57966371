/**
 * @file
 * Springs that best stand for a given linear stiffness: the one least-squares fit that
 * fitted springs (Lloyd, Székely and Harders 2007) and the condensed stiffness of a
 * coarse level of detail (doc/multiresolution.md) share.
 */
#pragma once

#include <lacerta/mesh/point.h>

#include <array>
#include <vector>

namespace lacerta::physics
{
  /**
   * The solution of the symmetric positive (semi)definite system @p a x = @p b (m x m,
   * row-major), by Cholesky factorisation; an unknown whose pivot vanishes (dependent
   * rows) gets 0.
   */
  std::vector<double>
  solve_symmetric(std::vector<double> a, std::vector<double> b, std::size_t m);

  /**
   * The stiffnesses k ≥ 0 of springs on @p edges (pairs of indices into @p points, at
   * rest) whose linear stiffness Σ k_e (n_e n_eᵀ) ⊗ [[1, -1], [-1, 1]] is nearest to
   * @p target (3n x 3n, row-major, n = points.size(), node-major: 3 i + d) in the
   * Frobenius norm. A spring cannot push back in tension, so an edge whose stiffness
   * comes out negative is dropped (k = 0) and the others are fitted again, until none
   * is negative.
   */
  std::vector<double>
  fit_spring_stiffnesses(const std::vector<mesh::Point3>                &points,
                         const std::vector<std::array<unsigned int, 2>> &edges,
                         const std::vector<double>                      &target);
} // namespace lacerta::physics
