#include <lacerta/base/exceptions.h>
#include <lacerta/physics/spring_fit.h>

#include <cmath>
#include <cstddef>

namespace lacerta::physics
{
  std::vector<double>
  solve_symmetric(std::vector<double> a, std::vector<double> b, const std::size_t m)
  {
    double largest = 0;
    for (std::size_t i = 0; i < m; ++i)
      largest = std::max(largest, a[i * m + i]);
    const double      tiny = 1e-12 * largest;
    std::vector<char> zero(m, 0);
    for (std::size_t j = 0; j < m; ++j)
    {
      double d = a[j * m + j];
      for (std::size_t k = 0; k < j; ++k)
        d -= a[j * m + k] * a[j * m + k];
      if (!(d > tiny))
      {
        zero[j] = 1;
        for (std::size_t i = j; i < m; ++i)
          a[i * m + j] = 0;
        continue;
      }
      const double l = std::sqrt(d);
      a[j * m + j]   = l;
      for (std::size_t i = j + 1; i < m; ++i)
      {
        double s = a[i * m + j];
        for (std::size_t k = 0; k < j; ++k)
          s -= a[i * m + k] * a[j * m + k];
        a[i * m + j] = s / l;
      }
    }
    // L y = b, then Lᵀ x = y, skipping the dropped pivots.
    for (std::size_t i = 0; i < m; ++i)
    {
      if (zero[i])
      {
        b[i] = 0;
        continue;
      }
      for (std::size_t k = 0; k < i; ++k)
        b[i] -= a[i * m + k] * b[k];
      b[i] /= a[i * m + i];
    }
    for (std::size_t i = m; i-- > 0;)
    {
      if (zero[i])
        continue;
      for (std::size_t k = i + 1; k < m; ++k)
        b[i] -= a[k * m + i] * b[k];
      b[i] /= a[i * m + i];
    }
    return b;
  }


  std::vector<double>
  fit_spring_stiffnesses(const std::vector<mesh::Point3>                &points,
                         const std::vector<std::array<unsigned int, 2>> &edges,
                         const std::vector<double>                      &target)
  {
    const std::size_t n = points.size(), m = edges.size();
    if (target.size() != 9 * n * n)
      throw_error("fit_spring_stiffnesses: internal error, the target has ",
                  target.size(),
                  " entries for ",
                  n,
                  " points.");
    std::vector<mesh::Point3> direction(m);
    for (std::size_t e = 0; e < m; ++e)
    {
      const mesh::Point3 d = mesh::sub(points[edges[e][1]], points[edges[e][0]]);
      direction[e]         = mesh::scale(1 / std::sqrt(mesh::dot(d, d)), d);
    }
    // <B_a, B_b> for unit springs a and b: (n_a·n_b)² times 4 on the same edge, 1 for
    // edges that share one end, 0 otherwise. <B_a, T> = n_aᵀ (T_uu + T_vv - T_uv -
    // T_vu) n_a for a = (u, v).
    std::vector<double> gram(m * m, 0.0), rhs(m, 0.0);
    for (std::size_t a = 0; a < m; ++a)
    {
      const auto [u, v] = edges[a];
      for (std::size_t b = 0; b < m; ++b)
      {
        const auto [s, t] = edges[b];
        const int shared  = (u == s) + (u == t) + (v == s) + (v == t);
        if (shared == 0)
          continue;
        const double c  = mesh::dot(direction[a], direction[b]);
        gram[a * m + b] = c * c * (shared == 2 ? 4.0 : 1.0);
      }
      const auto block = [&](const unsigned int i, const unsigned int j)
      {
        double sum = 0;
        for (unsigned int c = 0; c < 3; ++c)
          for (unsigned int d = 0; d < 3; ++d)
            sum +=
              direction[a][c] * target[(3 * i + c) * 3 * n + 3 * j + d] * direction[a][d];
        return sum;
      };
      rhs[a] = block(u, u) + block(v, v) - block(u, v) - block(v, u);
    }
    // Active set: fit on the edges still active, drop those that come out negative.
    std::vector<char>   active(m, 1);
    std::vector<double> k(m, 0.0);
    for (std::size_t pass = 0; pass <= m; ++pass)
    {
      std::vector<std::size_t> index;
      for (std::size_t e = 0; e < m; ++e)
        if (active[e])
          index.push_back(e);
      const std::size_t   r = index.size();
      std::vector<double> a(r * r), b(r);
      for (std::size_t i = 0; i < r; ++i)
      {
        for (std::size_t j = 0; j < r; ++j)
          a[i * r + j] = gram[index[i] * m + index[j]];
        b[i] = rhs[index[i]];
      }
      const std::vector<double> solution = solve_symmetric(a, b, r);
      std::fill(k.begin(), k.end(), 0.0);
      bool all_positive = true;
      for (std::size_t i = 0; i < r; ++i)
      {
        k[index[i]] = std::max(solution[i], 0.0);
        if (solution[i] < 0)
        {
          active[index[i]] = 0;
          all_positive     = false;
        }
      }
      if (all_positive)
        break;
    }
    return k;
  }
} // namespace lacerta::physics
