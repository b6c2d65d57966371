#include <lacerta/base/exceptions.h>
#include <lacerta/mesh/tet_mesh.h>
#include <lacerta/mt/coarse_stiffness.h>
#include <lacerta/physics/spring_fit.h>

#include <algorithm>
#include <cmath>
#include <iostream>

namespace lacerta::mt
{
  namespace
  {
    /**
     * The vertices of the fragments of one node and their linearised spring
     * stiffness (3n x 3n, node-major, row-major), with the removed vertex last.
     */
    struct Fragment
    {
      std::vector<std::uint32_t> vertices;
      std::vector<double>        stiffness;

      unsigned int
      local(const std::uint32_t v)
      {
        const auto at = std::find(vertices.begin(), vertices.end(), v);
        if (at != vertices.end())
          return static_cast<unsigned int>(at - vertices.begin());
        vertices.push_back(v);
        return static_cast<unsigned int>(vertices.size() - 1);
      }
    };


    /// S = K_cc - K_cp K_pp⁻¹ K_pc of @p k (3n x 3n) with p the last vertex: 3(n-1)
    /// squared. Throws if K_pp is singular (the removed vertex's springs do not
    /// span space).
    std::vector<double>
    condense_last_vertex(const std::vector<double> &k, const std::size_t n)
    {
      const std::size_t N = 3 * n, M = 3 * (n - 1);
      double            a[3][3];
      for (unsigned int r = 0; r < 3; ++r)
        for (unsigned int c = 0; c < 3; ++c)
          a[r][c] = k[(M + r) * N + M + c];
      const double det = a[0][0] * (a[1][1] * a[2][2] - a[1][2] * a[2][1])
                         - a[0][1] * (a[1][0] * a[2][2] - a[1][2] * a[2][0])
                         + a[0][2] * (a[1][0] * a[2][1] - a[1][1] * a[2][0]);
      const double scale = std::max({a[0][0], a[1][1], a[2][2]});
      if (!(std::abs(det) > 1e-12 * scale * scale * scale))
        throw_error("Multiresolution: internal error, a removed vertex's springs do "
                    "not span space.");
      double inverse[3][3];
      for (unsigned int r = 0; r < 3; ++r)
        for (unsigned int c = 0; c < 3; ++c)
        {
          const unsigned int r1 = (c + 1) % 3, r2 = (c + 2) % 3, c1 = (r + 1) % 3,
                             c2 = (r + 2) % 3;
          inverse[r][c]         = (a[r1][c1] * a[r2][c2] - a[r1][c2] * a[r2][c1]) / det;
        }
      // K_pp⁻¹ K_pc, 3 x M.
      std::vector<double> g(3 * M, 0.0);
      for (unsigned int r = 0; r < 3; ++r)
        for (std::size_t j = 0; j < M; ++j)
          for (unsigned int s = 0; s < 3; ++s)
            g[r * M + j] += inverse[r][s] * k[(M + s) * N + j];
      std::vector<double> s(M * M);
      for (std::size_t i = 0; i < M; ++i)
        for (std::size_t j = 0; j < M; ++j)
        {
          double v = k[i * N + j];
          for (unsigned int r = 0; r < 3; ++r)
            v -= k[i * N + M + r] * g[r * M + j];
          s[i * M + j] = v;
        }
      return s;
    }

    /// The six unit strains (symmetric), xx, yy, zz, yz, xz, xy.
    constexpr unsigned int strain_axes[6][2] =
      {{0, 0}, {1, 1}, {2, 2}, {1, 2}, {0, 2}, {0, 1}};

    /// u_aᵀ K u_b for the displacements u = ε_a x of the six unit strains, of a
    /// stiffness @p k (3n x 3n) on @p points.
    std::array<double, 36>
    strain_energy_matrix(const std::vector<mesh::Point3> &points,
                         const std::vector<double>       &k)
    {
      const std::size_t   n = points.size(), N = 3 * n;
      std::vector<double> u(6 * N, 0.0);
      for (unsigned int a = 0; a < 6; ++a)
        for (std::size_t v = 0; v < n; ++v)
        {
          const auto [i, j] = strain_axes[a];
          u[a * N + 3 * v + i] += 0.5 * points[v][j];
          u[a * N + 3 * v + j] += 0.5 * points[v][i];
        }
      std::array<double, 36> m{};
      std::vector<double>    ku(N);
      for (unsigned int b = 0; b < 6; ++b)
      {
        for (std::size_t r = 0; r < N; ++r)
        {
          double sum = 0;
          for (std::size_t c = 0; c < N; ++c)
            sum += k[r * N + c] * u[b * N + c];
          ku[r] = sum;
        }
        for (unsigned int a = 0; a < 6; ++a)
        {
          double sum = 0;
          for (std::size_t r = 0; r < N; ++r)
            sum += u[a * N + r] * ku[r];
          m[6 * a + b] = sum;
        }
      }
      return m;
    }


    /// strain_energy_matrix() of a spring of stiffness @p k on @p edge.
    std::array<double, 36>
    edge_strain_energy_matrix(const std::vector<mesh::Point3>   &points,
                              const std::array<unsigned int, 2> &edge,
                              const double                       k)
    {
      const mesh::Point3 d = mesh::sub(points[edge[1]], points[edge[0]]);
      // The elongation of the edge under unit strain a, times its length: dᵀ ε_a d / L.
      std::array<double, 6> s;
      const double          length2 = mesh::dot(d, d);
      for (unsigned int a = 0; a < 6; ++a)
      {
        const auto [i, j] = strain_axes[a];
        s[a]              = d[i] * d[j] / std::sqrt(length2);
      }
      std::array<double, 36> m;
      for (unsigned int a = 0; a < 6; ++a)
        for (unsigned int b = 0; b < 6; ++b)
          m[6 * a + b] = k * s[a] * s[b];
      return m;
    }


    /// strain_energy_matrix() of springs of stiffness @p k on @p edges.
    std::array<double, 36>
    spring_strain_energy_matrix(const std::vector<mesh::Point3>                &points,
                                const std::vector<std::array<unsigned int, 2>> &edges,
                                const std::vector<double>                      &k)
    {
      std::array<double, 36> m{};
      for (std::size_t e = 0; e < edges.size(); ++e)
      {
        const std::array<double, 36> one =
          edge_strain_energy_matrix(points, edges[e], k[e]);
        for (unsigned int i = 0; i < 36; ++i)
          m[i] += one[i];
      }
      return m;
    }


    /**
     * Per edge, the factor x_e ≥ floor on the scaled rule's stiffness factor k_e that
     * makes the springs' energies under the six unit strains nearest to @p target, with
     * a small pull of every x_e towards 1 that picks, among the many fits, the one
     * nearest to the rule.
     */
    std::vector<double>
    fit_edge_scales(const std::vector<mesh::Point3>                &points,
                    const std::vector<std::array<unsigned int, 2>> &edges,
                    const std::vector<double>                      &rule_k,
                    const double                                    factor,
                    const std::array<double, 36>                   &target)
    {
      const std::size_t                   m = edges.size();
      std::vector<std::array<double, 36>> unit(m);
      for (std::size_t e = 0; e < m; ++e)
        unit[e] = edge_strain_energy_matrix(points, edges[e], factor * rule_k[e]);
      std::vector<double> gram(m * m, 0.0), rhs(m, 0.0);
      double              trace = 0;
      for (std::size_t a = 0; a < m; ++a)
      {
        for (std::size_t b = 0; b < m; ++b)
          for (unsigned int i = 0; i < 36; ++i)
            gram[a * m + b] += unit[a][i] * unit[b][i];
        for (unsigned int i = 0; i < 36; ++i)
          rhs[a] += unit[a][i] * target[i];
        trace += gram[a * m + a];
      }
      const double        pull = 1e-2 * trace / m, floor = 0.05;
      std::vector<char>   fixed(m, 0);
      std::vector<double> x(m, 1.0);
      for (std::size_t pass = 0; pass <= m; ++pass)
      {
        // Solve (G + pull I) x = rhs + pull on the free edges, the fixed at floor.
        std::vector<std::size_t> index;
        for (std::size_t e = 0; e < m; ++e)
          if (!fixed[e])
            index.push_back(e);
        const std::size_t   r = index.size();
        std::vector<double> a(r * r), b(r);
        for (std::size_t i = 0; i < r; ++i)
        {
          b[i] = rhs[index[i]] + pull;
          for (std::size_t e = 0; e < m; ++e)
            if (fixed[e])
              b[i] -= gram[index[i] * m + e] * floor;
          for (std::size_t j = 0; j < r; ++j)
            a[i * r + j] = gram[index[i] * m + index[j]] + (i == j ? pull : 0.0);
        }
        const std::vector<double> solution = physics::solve_symmetric(a, b, r);
        bool                      done     = true;
        for (std::size_t i = 0; i < r; ++i)
        {
          x[index[i]] = solution[i];
          if (solution[i] < floor)
          {
            fixed[index[i]] = 1;
            x[index[i]]     = floor;
            done            = false;
          }
        }
        if (done)
          break;
      }
      return x;
    }
  } // namespace


  std::vector<std::array<double, 6>>
  condensed_edge_stiffnesses(const MultiTriangulation &mt, const EdgeStiffnessRule &rule)
  {
    std::vector<std::array<double, 6>> k(mt.n_tets());
    for (std::uint32_t t = 0; t < mt.n_tets(); ++t)
      if (mt.destroyer[t] == mesh::invalid_index)
        k[t] = rule(mt.corners(t));
    Fragment                                 fragment;
    std::vector<mesh::Point3>                points;
    std::vector<std::array<unsigned int, 2>> edges;
    std::vector<std::uint32_t>               coarse;
    // Replayed in the order of the decimation: the last node's collapse came first.
    for (unsigned int j = mt.n_nodes(); j-- > 1;)
    {
      fragment.vertices.clear();
      coarse.clear();
      mt.for_each_coarse(j, [&](const std::uint32_t t) { coarse.push_back(t); });
      for (const std::uint32_t t : coarse)
        for (const std::uint32_t v : mt.tets[t])
          fragment.local(v);
      const unsigned int p = fragment.local(mt.node_vertex[j]);
      const std::size_t  n = fragment.vertices.size();
      if (p != n - 1)
        throw_error("Multiresolution: internal error, node ",
                    j,
                    "'s coarse fragment holds the vertex it removes.");
      // The fine fragment's linearised springs.
      fragment.stiffness.assign(9 * n * n, 0.0);
      mt.for_each_fine(j,
                       [&](const std::uint32_t t)
                       {
                         for (unsigned int e = 0; e < 6; ++e)
                         {
                           const auto [i0, i1]  = mesh::TetMesh::edge_vertices[e];
                           const unsigned int a = fragment.local(mt.tets[t][i0]);
                           const unsigned int b = fragment.local(mt.tets[t][i1]);
                           if (a >= n || b >= n)
                             throw_error("Multiresolution: internal error, node ",
                                         j,
                                         "'s fragments have different vertices.");
                           const mesh::Point3 d = mesh::sub(mt.vertices[mt.tets[t][i1]],
                                                            mt.vertices[mt.tets[t][i0]]);
                           const double       f = k[t][e] / mesh::dot(d, d);
                           for (unsigned int r = 0; r < 3; ++r)
                             for (unsigned int c = 0; c < 3; ++c)
                             {
                               const double v = f * d[r] * d[c];
                               fragment.stiffness[(3 * a + r) * 3 * n + 3 * a + c] += v;
                               fragment.stiffness[(3 * b + r) * 3 * n + 3 * b + c] += v;
                               fragment.stiffness[(3 * a + r) * 3 * n + 3 * b + c] -= v;
                               fragment.stiffness[(3 * b + r) * 3 * n + 3 * a + c] -= v;
                             }
                         }
                       });
      const std::vector<double> condensed = condense_last_vertex(fragment.stiffness, n);
      // The coarse fragment's edges, and each coarse tetrahedron's rule weights.
      points.assign(fragment.vertices.size() - 1, {});
      for (std::size_t i = 0; i + 1 < n; ++i)
        points[i] = mt.vertices[fragment.vertices[i]];
      edges.clear();
      std::vector<std::array<unsigned int, 6>> edge_of(coarse.size());
      std::vector<std::array<double, 6>>       weight(coarse.size());
      for (std::size_t c = 0; c < coarse.size(); ++c)
      {
        weight[c] = rule(mt.corners(coarse[c]));
        for (unsigned int e = 0; e < 6; ++e)
        {
          const auto [i0, i1] = mesh::TetMesh::edge_vertices[e];
          std::array<unsigned int, 2> key{{fragment.local(mt.tets[coarse[c]][i0]),
                                           fragment.local(mt.tets[coarse[c]][i1])}};
          if (key[0] > key[1])
            std::swap(key[0], key[1]);
          const auto at = std::find(edges.begin(), edges.end(), key);
          edge_of[c][e] = static_cast<unsigned int>(at - edges.begin());
          if (at == edges.end())
            edges.push_back(key);
        }
      }
      // The rule's springs on the coarse fragment, and the scale that makes their
      // energy under uniform strains nearest to the condensed fine fragment's.
      std::vector<double> rule_k(edges.size(), 0.0);
      for (std::size_t c = 0; c < coarse.size(); ++c)
        for (unsigned int e = 0; e < 6; ++e)
          rule_k[edge_of[c][e]] += weight[c][e];
      const auto strain_energies = strain_energy_matrix(points, condensed);
      const auto rule_energies   = spring_strain_energy_matrix(points, edges, rule_k);
      double     dot_rs = 0, dot_rr = 0;
      for (unsigned int i = 0; i < 36; ++i)
      {
        dot_rs += rule_energies[i] * strain_energies[i];
        dot_rr += rule_energies[i] * rule_energies[i];
      }
      const double              factor = dot_rs / dot_rr;
      const std::vector<double> scale =
        fit_edge_scales(points, edges, rule_k, factor, strain_energies);
      for (std::size_t c = 0; c < coarse.size(); ++c)
        for (unsigned int e = 0; e < 6; ++e)
          k[coarse[c]][e] = factor * scale[edge_of[c][e]] * weight[c][e];
    }
    return k;
  }
} // namespace lacerta::mt
