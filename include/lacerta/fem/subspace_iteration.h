/**
 * @file
 * The lowest eigenpairs of K x = λ M x by subspace iteration, for any vector type:
 * shared by the FEM reference (Trilinos, MPI) and the spring model (serial, direct).
 * Include only in .cc files that compute frequencies.
 */
#pragma once

#include <deal.II/lac/full_matrix.h>
#include <deal.II/lac/lapack_full_matrix.h>
#include <deal.II/lac/vector.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <vector>

namespace lacerta::fem
{
  /**
   * The @p n lowest eigenvalues λ of K x = λ M x, K and M symmetric positive definite on
   * the space the operators act on. Each iteration applies K⁻¹M to a block of
   * p = n + max(n, 4) vectors, M-orthonormalises it and makes the Rayleigh-Ritz step in
   * it; the iteration stops when the wanted eigenvalues change by less than
   * @p tolerance relative. @p start fills a vector with a start guess (vector number j);
   * @p restrict_to_free zeroes the prescribed entries, so that they never enter.
   */
  template <typename VectorType>
  std::vector<double>
  lowest_eigenvalues(const unsigned int                                           n,
                     const std::function<void(VectorType &, unsigned int)>       &start,
                     const std::function<void(VectorType &, const VectorType &)> &apply_k,
                     const std::function<void(VectorType &, const VectorType &)> &apply_m,
                     const std::function<void(VectorType &, const VectorType &)> &solve_k,
                     const std::function<void(VectorType &)> &restrict_to_free,
                     const double                             tolerance      = 1e-9,
                     const unsigned int                       max_iterations = 500)
  {
    const unsigned int      p = n + std::max(n, 4u);
    std::vector<VectorType> x(p), y(p);
    VectorType              tmp;
    for (unsigned int j = 0; j < p; ++j)
    {
      start(x[j], j);
      restrict_to_free(x[j]);
      y[j].reinit(x[j]);
    }
    tmp.reinit(x[0]);

    std::vector<double> lambda(n, 0.0), previous(n, -1.0);
    for (unsigned int iteration = 0; iteration < max_iterations; ++iteration)
    {
      for (unsigned int j = 0; j < p; ++j)
      {
        apply_m(tmp, x[j]);
        restrict_to_free(tmp);
        solve_k(y[j], tmp);
        restrict_to_free(y[j]);
      }
      // M-orthonormalise the block (modified Gram-Schmidt, twice for stability).
      for (unsigned int pass = 0; pass < 2; ++pass)
        for (unsigned int j = 0; j < p; ++j)
        {
          for (unsigned int i = 0; i < j; ++i)
          {
            apply_m(tmp, y[i]);
            y[j].add(-(tmp * y[j]), y[i]);
          }
          apply_m(tmp, y[j]);
          y[j] /= std::sqrt(tmp * y[j]);
        }
      // Rayleigh-Ritz: the projected K in the M-orthonormal block.
      dealii::LAPACKFullMatrix<double> projected(p, p);
      for (unsigned int j = 0; j < p; ++j)
      {
        apply_k(tmp, y[j]);
        for (unsigned int i = 0; i <= j; ++i)
          projected(i, j) = projected(j, i) = y[i] * tmp;
      }
      const double               bound = projected.frobenius_norm() + 1.0;
      dealii::Vector<double>     values;
      dealii::FullMatrix<double> vectors;
      projected.compute_eigenvalues_symmetric(-bound, bound, 0.0, values, vectors);
      // Ritz vectors, lowest first (LAPACK returns them in ascending order).
      for (unsigned int j = 0; j < p; ++j)
      {
        x[j] = 0;
        for (unsigned int i = 0; i < p; ++i)
          x[j].add(vectors(i, j), y[i]);
      }
      bool converged = true;
      for (unsigned int k = 0; k < n; ++k)
      {
        lambda[k] = values[k];
        converged =
          converged
          && std::abs(lambda[k] - previous[k]) <= tolerance * std::abs(lambda[k]);
      }
      if (converged)
        break;
      previous = lambda;
    }
    return lambda;
  }


  /// Eigenvalues λ = ω² ((rad/s)²) as frequencies ω / 2π (Hz).
  inline std::vector<double>
  to_frequencies(std::vector<double> lambda)
  {
    for (double &l : lambda)
      l = std::sqrt(std::max(l, 0.0)) / (2 * M_PI);
    return lambda;
  }
} // namespace lacerta::fem
