#include <lacerta/base/archive.h>
#include <lacerta/base/exceptions.h>
#include <lacerta/base/sort_ids.h>
#include <lacerta/mesh/tet_mesh.h>
#include <lacerta/physics/force_model.h>
#include <lacerta/physics/particle_system.h>
#include <lacerta/physics/stability.h>
#include <lacerta/physics/system_ranges.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <sstream>
#include <tuple>

namespace lacerta::physics
{
  namespace
  {
    /// Largest eigenvalue of a symmetric 3x3 matrix (trigonometric closed form).
    double
    largest_eigenvalue(const std::array<double, 6> &m) // xx, yy, zz, xy, xz, yz
    {
      const double p1 = m[3] * m[3] + m[4] * m[4] + m[5] * m[5];
      const double q  = (m[0] + m[1] + m[2]) / 3.0;
      if (p1 <= 1e-30 * (q * q + 1e-300))
        return std::max({m[0], m[1], m[2]});
      const double a = m[0] - q, b = m[1] - q, c = m[2] - q;
      const double p = std::sqrt((a * a + b * b + c * c + 2 * p1) / 6.0);
      // det((M - qI)/p) / 2
      const double det = a * (b * c - m[5] * m[5]) - m[3] * (m[3] * c - m[5] * m[4])
                         + m[4] * (m[3] * m[5] - b * m[4]);
      const double r = std::clamp(det / (2 * p * p * p), -1.0, 1.0);
      return q + 2 * p * std::cos(std::acos(r) / 3.0);
    }


    std::string
    describe_particle(const ParticleSystem &system, const unsigned int i)
    {
      std::ostringstream s;
      s.precision(6);
      const auto &x = system.rest_position();
      s << "particle " << i << " (rest position " << x[3 * i] << ", " << x[3 * i + 1]
        << ", " << x[3 * i + 2] << ")";
      return s.str();
    }


    /// Energies far below a spring stretched to twice its length are noise.
    double
    noise_energy(const ParticleSystem &system)
    {
      double spring_energy = 0;
      for (std::size_t s = 0; s < system.springs.size(); ++s)
        spring_energy += system.springs.stiffness[s] * system.springs.rest_length[s]
                         * system.springs.rest_length[s];
      return 1e-12 * spring_energy;
    }
  } // namespace


  namespace
  {
    /// Adds the symmetric 3x3 block @p b (xx, yy, zz, xy, xz, yz) to @p sum.
    void
    add_block(std::array<double, 6> &sum, const std::array<double, 6> &b)
    {
      for (unsigned int c = 0; c < 6; ++c)
        sum[c] += b[c];
    }


    /**
     * The tangent stiffness K_e = (k - g) n nᵀ + g I of spring @p s at positions @p x
     * (k its stiffness times @p scale, g = k (1 - L0/L) the geometric stiffness) as a
     * symmetric block, in @p norm the bound max(k, |g|) of ||K_e||, and in
     * @p absolute the block |K_e| = (k - |g|) n nᵀ + |g| I, positive semi-definite
     * with -|K_e| ≤ K_e ≤ |K_e|.
     */
    std::array<double, 6>
    spring_tangent_block(const SpringSet       &springs,
                         const std::size_t      s,
                         const double          *x,
                         const double           scale,
                         double                &norm,
                         std::array<double, 6> &absolute)
    {
      const unsigned int i = springs.a[s], j = springs.b[s];
      double             d[3]   = {x[3 * j] - x[3 * i],
                                   x[3 * j + 1] - x[3 * i + 1],
                                   x[3 * j + 2] - x[3 * i + 2]};
      const double       length = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
      for (double &c : d)
        c /= length;
      const double k         = scale * springs.stiffness[s];
      const double geometric = k * (1.0 - springs.rest_length[s] / length);
      norm                   = std::max(k, std::abs(geometric));
      const double g         = std::abs(geometric);
      absolute               = {(k - g) * d[0] * d[0] + g,
                                (k - g) * d[1] * d[1] + g,
                                (k - g) * d[2] * d[2] + g,
                                (k - g) * d[0] * d[1],
                                (k - g) * d[0] * d[2],
                                (k - g) * d[1] * d[2]};
      return {(k - geometric) * d[0] * d[0] + geometric,
              (k - geometric) * d[1] * d[1] + geometric,
              (k - geometric) * d[2] * d[2] + geometric,
              (k - geometric) * d[0] * d[1],
              (k - geometric) * d[0] * d[2],
              (k - geometric) * d[1] * d[2]};
    }


    /**
     * The Gershgorin terms of one element stiffness @p K: calls @p diagonal(a, block)
     * with the symmetric part of the diagonal block of each local vertex a, and
     * @p off_diagonal(e, norm) with the spectral norm of the off-diagonal block of each
     * local edge e.
     */
    template <typename Diagonal, typename OffDiagonal>
    void
    element_terms(const ForceModel::ElementStiffness &K,
                  const Diagonal                     &diagonal,
                  const OffDiagonal                  &off_diagonal)
    {
      const auto at = [&](unsigned int a, unsigned int r, unsigned int b, unsigned int c)
      { return K[12 * (3 * a + r) + 3 * b + c]; };
      for (unsigned int a = 0; a < 4; ++a)
        diagonal(a,
                 std::array<double, 6>{at(a, 0, a, 0),
                                       at(a, 1, a, 1),
                                       at(a, 2, a, 2),
                                       0.5 * (at(a, 0, a, 1) + at(a, 1, a, 0)),
                                       0.5 * (at(a, 0, a, 2) + at(a, 2, a, 0)),
                                       0.5 * (at(a, 1, a, 2) + at(a, 2, a, 1))});
      for (unsigned int e = 0; e < 6; ++e)
      {
        const auto [a, b] = mesh::TetMesh::edge_vertices[e];
        // ||K_ab||² = λ_max(K_abᵀ K_ab).
        std::array<double, 6> gram{};
        const unsigned int pairs[6][2] = {{0, 0}, {1, 1}, {2, 2}, {0, 1}, {0, 2}, {1, 2}};
        for (unsigned int g = 0; g < 6; ++g)
          for (unsigned int r = 0; r < 3; ++r)
            gram[g] += at(a, r, b, pairs[g][0]) * at(a, r, b, pairs[g][1]);
        off_diagonal(e, std::sqrt(std::max(0.0, largest_eigenvalue(gram))));
      }
    }


    /// Whether particle @p i has a row in the bound: free, with a mass.
    bool
    has_row(const ParticleSystem &system, const unsigned int i)
    {
      return system.free[i] > 0 && system.mass[i] > 0;
    }


    /// The factor the force model applies to the springs (1 without a model).
    double
    spring_scale(const ParticleSystem &system)
    {
      return system.has_force_model() ? system.force_model().spring_stiffness_scale()
                                      : 1.0;
    }


    /**
     * The bound of a row's diagonal terms for weighted_frequency_bounds(): the larger
     * of λ_max(S + E) and λ_max(S - E) for the springs' sum @p springs S = Σ (1 + t_e)
     * |K_e| and the force model's diagonal element block @p element E; the first
     * bounds the row's share of xᵀ K x, the second that of -xᵀ K x.
     */
    double
    row_block_bound(const std::array<double, 6> &springs,
                    const std::array<double, 6> &element)
    {
      std::array<double, 6> plus, minus;
      for (unsigned int c = 0; c < 6; ++c)
      {
        plus[c]  = springs[c] + element[c];
        minus[c] = springs[c] - element[c];
      }
      return std::max(largest_eigenvalue(plus), largest_eigenvalue(minus));
    }


    /**
     * What the weighted terms of row p need of its own particle, with row weight d_p
     * and mass m_p: down = sqrt(m_p) / d_p and inverse = 1 / (sqrt(m_p) d_p); of the
     * other end q of a spring they need up_factor(q) = d_q / sqrt(m_q). The terms then
     * take products only (add_weighted_spring_terms()).
     */
    struct RowFactors
    {
      double down, inverse;
    };


    /// The RowFactors of particle @p p with the row @p weights.
    RowFactors
    row_factors(const ParticleSystem      &system,
                const std::vector<double> &weights,
                const unsigned int         p)
    {
      const double root = std::sqrt(system.mass[p]);
      return {root / weights[p], 1 / (root * weights[p])};
    }


    /// d_q / sqrt(m_q) of particle @p q with the row @p weights (RowFactors).
    double
    up_factor(const ParticleSystem      &system,
              const std::vector<double> &weights,
              const unsigned int         q)
    {
      return weights[q] / std::sqrt(system.mass[q]);
    }


    /**
     * Adds the terms of the spring between row @p p and particle @p q (the row's
     * factors @p fp, q's up_factor() @p up_q) to row p of the weighted bound
     * (weighted_frequency_bounds()): (1 + t) |K_e| to the row's @p block,
     * t = sqrt(m_p / m_q) d_q / d_p if both ends are free (0 if q is held), and the
     * norm @p element_norm of the force model's off-diagonal block on the edge, over
     * sqrt(m_p m_q) times d_q / d_p, to @p off_diagonal.
     */
    void
    add_weighted_spring_terms(const ParticleSystem        &system,
                              const unsigned int           p,
                              const unsigned int           q,
                              const RowFactors            &fp,
                              const double                 up_q,
                              const std::array<double, 6> &absolute,
                              const double                 element_norm,
                              std::array<double, 6>       &block,
                              double                      &off_diagonal)
    {
      const bool   coupled = system.free[p] > 0 && system.free[q] > 0;
      const double t       = coupled ? fp.down * up_q : 0.0;
      for (unsigned int c = 0; c < 6; ++c)
        block[c] += (1 + t) * absolute[c];
      if (coupled && element_norm > 0)
        off_diagonal += element_norm * (up_q * fp.inverse);
    }
  } // namespace


  GershgorinTerms
  gershgorin_terms(const ParticleSystem &system, const double *x)
  {
    const unsigned int n       = system.n_particles();
    const SpringSet   &springs = system.springs;
    // A system without a force model yet (a bare spring network) is bounded by its
    // springs as they are.
    const double scale = spring_scale(system);
    // The tangent block of each spring, and their sum at each particle.
    std::vector<std::array<double, 6>> tangent(springs.size());
    std::vector<std::array<double, 6>> blocks(n, std::array<double, 6>{});
    std::vector<double>                pair_norm(springs.size(), 0.0);
    std::vector<double>                element_norm(springs.size(), 0.0);
    GershgorinTerms                    terms;
    terms.diagonal.assign(n, 0.0);
    terms.coupling.assign(springs.size(), 0.0);
    terms.stiffest_spring.assign(n, 0);
    terms.spring_block.resize(springs.size());
    terms.element_block.assign(n, std::array<double, 6>{});
    terms.element_coupling.assign(springs.size(), 0.0);

    for_each_spring_range(system,
                          [&](const std::size_t begin, const std::size_t end)
                          {
                            for (std::size_t s = begin; s < end; ++s)
                              tangent[s] = spring_tangent_block(springs,
                                                                s,
                                                                x,
                                                                scale,
                                                                pair_norm[s],
                                                                terms.spring_block[s]);
                          });
    for_each_particle_range(system,
                            [&](const unsigned int begin, const unsigned int end)
                            {
                              for (std::size_t s = 0; s < springs.size(); ++s)
                                for (const unsigned int p : {springs.a[s], springs.b[s]})
                                  if (p >= begin && p < end)
                                    add_block(blocks[p], tangent[s]);
                            });
    if (system.has_force_model())
      system.force_model().for_each_element_stiffness(
        system,
        x,
        [&](const unsigned int t, const ForceModel::ElementStiffness &K)
        {
          const mesh::Tet &tet = system.mesh->tet(t);
          element_terms(
            K,
            [&](unsigned int a, const std::array<double, 6> &b)
            {
              add_block(blocks[tet[a]], b);
              add_block(terms.element_block[tet[a]], b);
            },
            [&](unsigned int e, double norm)
            {
              pair_norm[system.mesh->tet_edges(t)[e]] += norm;
              element_norm[system.mesh->tet_edges(t)[e]] += norm;
            });
        });

    for_each_spring_range(system,
                          [&](const std::size_t begin, const std::size_t end)
                          {
                            for (std::size_t s = begin; s < end; ++s)
                              if (system.free[springs.a[s]] > 0
                                  && system.free[springs.b[s]] > 0)
                              {
                                terms.coupling[s]         = pair_norm[s];
                                terms.element_coupling[s] = element_norm[s];
                              }
                          });
    for_each_particle_range(system,
                            [&](const unsigned int begin, const unsigned int end)
                            {
                              // The first of the springs with the largest norm at each
                              // particle.
                              std::vector<double> stiffest(end - begin, 0.0);
                              for (std::size_t s = 0; s < springs.size(); ++s)
                                for (const unsigned int p : {springs.a[s], springs.b[s]})
                                  if (p >= begin && p < end
                                      && pair_norm[s] > stiffest[p - begin])
                                  {
                                    stiffest[p - begin] = pair_norm[s];
                                    terms.stiffest_spring[p] =
                                      static_cast<unsigned int>(s);
                                  }
                              for (unsigned int i = begin; i < end; ++i)
                                terms.diagonal[i] = largest_eigenvalue(blocks[i]);
                            });
    return terms;
  }


  namespace
  {
    /**
     * The mass-independent terms of the rows @p rows (distinct) into @p w: the
     * diagonal blocks Σ_e K_e of every row (w.blocks) and ||K_e|| of every spring at a
     * row (w.pair_norm, for w.springs, in spring order), from the springs and the force
     * model's tetrahedra around the rows at positions @p x.
     */
    void
    gather_row_terms(const ParticleSystem            &system,
                     const double                    *x,
                     const std::vector<unsigned int> &rows,
                     GershgorinRowScratch            &w)
    {
      const mesh::TetMesh &mesh    = *system.mesh;
      const SpringSet     &springs = system.springs;
      ++w.stamp;
      w.row_of.resize(system.n_particles(), 0);
      w.row_stamp.resize(system.n_particles(), 0);
      w.spring_stamp.resize(springs.size(), 0);
      w.spring_of.resize(springs.size(), 0);
      w.tet_stamp.resize(mesh.n_tets(), 0);
      for (std::size_t r = 0; r < rows.size(); ++r)
      {
        w.row_stamp[rows[r]] = w.stamp;
        w.row_of[rows[r]]    = static_cast<unsigned int>(r);
      }
      const auto is_row = [&](const unsigned int p) { return w.row_stamp[p] == w.stamp; };
      // The tetrahedra around the rows, and the springs (edges) at the rows.
      w.tets.clear();
      w.springs.clear();
      for (const unsigned int p : rows)
        for (const unsigned int t : mesh.tets_of_vertex(p))
        {
          if (w.tet_stamp[t] == w.stamp)
            continue;
          w.tet_stamp[t] = w.stamp;
          w.tets.push_back(t);
          for (const unsigned int s : mesh.tet_edges(t))
            if (w.spring_stamp[s] != w.stamp
                && (is_row(springs.a[s]) || is_row(springs.b[s])))
            {
              w.spring_stamp[s] = w.stamp;
              w.springs.push_back(s);
            }
        }
      // In spring order, so that the stiffest spring is chosen as gershgorin_terms()
      // chooses it among equals.
      sort_ids(w.springs, w.sorted_springs);
      for (std::size_t k = 0; k < w.springs.size(); ++k)
        w.spring_of[w.springs[k]] = static_cast<unsigned int>(k);
      w.blocks.assign(rows.size(), std::array<double, 6>{});
      w.element_blocks.assign(rows.size(), std::array<double, 6>{});
      w.pair_norm.assign(w.springs.size(), 0.0);
      w.element_norm.assign(w.springs.size(), 0.0);
      w.spring_blocks.resize(w.springs.size());
      const double scale = spring_scale(system);
      for (std::size_t k = 0; k < w.springs.size(); ++k)
      {
        const unsigned int          s = w.springs[k];
        const std::array<double, 6> block =
          spring_tangent_block(springs, s, x, scale, w.pair_norm[k], w.spring_blocks[k]);
        for (const unsigned int p : {springs.a[s], springs.b[s]})
          if (is_row(p))
            add_block(w.blocks[w.row_of[p]], block);
      }
      if (system.has_force_model())
        system.force_model().for_each_element_stiffness_of(
          system,
          x,
          w.tets,
          [&](const unsigned int t, const ForceModel::ElementStiffness &K)
          {
            const mesh::Tet &tet = mesh.tet(t);
            element_terms(
              K,
              [&](unsigned int a, const std::array<double, 6> &b)
              {
                if (is_row(tet[a]))
                {
                  add_block(w.blocks[w.row_of[tet[a]]], b);
                  add_block(w.element_blocks[w.row_of[tet[a]]], b);
                }
              },
              [&](unsigned int e, double norm)
              {
                const unsigned int s = mesh.tet_edges(t)[e];
                if (w.spring_stamp[s] == w.stamp)
                {
                  w.pair_norm[w.spring_of[s]] += norm;
                  w.element_norm[w.spring_of[s]] += norm;
                }
              });
          });
    }


    /**
     * The rows λ_i of weighted_frequency_bounds() with @p weights for the first @p n
     * of the rows @p rows gathered in @p w (gather_row_terms()), into @p lambda; the
     * stiffest spring at each into @p stiffest_spring unless it is nullptr. Reads the
     * weights of the rows' neighbours.
     */
    void
    weighted_rows(const ParticleSystem            &system,
                  const std::vector<unsigned int> &rows,
                  const std::size_t                n,
                  const std::vector<double>       &weights,
                  GershgorinRowScratch            &w,
                  double                          *lambda,
                  unsigned int                    *stiffest_spring)
    {
      const SpringSet &springs = system.springs;
      w.row_blocks.assign(n, std::array<double, 6>{});
      w.off_diagonal.assign(n, 0.0);
      w.stiffest.assign(n, 0.0);
      w.row_down.resize(n);
      w.row_inverse.resize(n);
      for (std::size_t r = 0; r < n; ++r)
      {
        const RowFactors f = row_factors(system, weights, rows[r]);
        w.row_down[r]      = f.down;
        w.row_inverse[r]   = f.inverse;
      }
      for (std::size_t r = 0; r < n && stiffest_spring != nullptr; ++r)
        stiffest_spring[r] = 0;
      for (std::size_t k = 0; k < w.springs.size(); ++k)
      {
        const unsigned int s = w.springs[k], i = springs.a[s], j = springs.b[s];
        for (const auto &[p, q] : {std::pair{i, j}, std::pair{j, i}})
          if (w.row_stamp[p] == w.stamp && w.row_of[p] < n)
          {
            const unsigned int r = w.row_of[p];
            add_weighted_spring_terms(system,
                                      p,
                                      q,
                                      RowFactors{w.row_down[r], w.row_inverse[r]},
                                      up_factor(system, weights, q),
                                      w.spring_blocks[k],
                                      w.element_norm[k],
                                      w.row_blocks[r],
                                      w.off_diagonal[r]);
            if (stiffest_spring != nullptr && w.pair_norm[k] > w.stiffest[r])
            {
              w.stiffest[r]      = w.pair_norm[k];
              stiffest_spring[r] = s;
            }
          }
      }
      for (std::size_t r = 0; r < n; ++r)
        lambda[r] =
          has_row(system, rows[r])
            ? row_block_bound(w.row_blocks[r], w.element_blocks[r]) / system.mass[rows[r]]
                + w.off_diagonal[r]
            : 0.0;
    }
  } // namespace


  void
  gershgorin_rows(const ParticleSystem            &system,
                  const double                    *x,
                  const std::vector<unsigned int> &rows,
                  const std::size_t                n_reweighted,
                  std::vector<double>             &first_weights,
                  std::vector<double>             &weights,
                  GershgorinRowScratch            &scratch,
                  double                          *lambda,
                  unsigned int                    *stiffest_spring)
  {
    const SpringSet      &springs = system.springs;
    GershgorinRowScratch &w       = scratch;
    gather_row_terms(system, x, rows, w);
    const auto is_row = [&](const unsigned int p) { return w.row_stamp[p] == w.stamp; };
    // The first weights of the first rows: their block Gershgorin rows, as
    // squared_frequency_bounds() makes them from gershgorin_terms().
    w.diagonal.resize(n_reweighted);
    w.off_diagonal.assign(n_reweighted, 0.0);
    for (std::size_t r = 0; r < n_reweighted; ++r)
      w.diagonal[r] = has_row(system, rows[r])
                        ? largest_eigenvalue(w.blocks[r]) / system.mass[rows[r]]
                        : 0.0;
    for (std::size_t k = 0; k < w.springs.size() && n_reweighted > 0; ++k)
    {
      const unsigned int s = w.springs[k], i = springs.a[s], j = springs.b[s];
      if (!(system.free[i] > 0 && system.free[j] > 0 && w.pair_norm[k] > 0))
        continue;
      const double c = w.pair_norm[k] / std::sqrt(system.mass[i] * system.mass[j]);
      for (const unsigned int p : {i, j})
        if (is_row(p) && w.row_of[p] < n_reweighted)
          w.off_diagonal[w.row_of[p]] += c;
    }
    for (std::size_t r = 0; r < n_reweighted; ++r)
      first_weights[rows[r]] = gershgorin_row_weight(
        has_row(system, rows[r]) ? w.diagonal[r] + w.off_diagonal[r] : 0.0);
    // Their weights, one step on (refined_row_weights()).
    w.refined.resize(n_reweighted);
    weighted_rows(
      system, rows, n_reweighted, first_weights, w, w.refined.data(), nullptr);
    for (std::size_t r = 0; r < n_reweighted; ++r)
      weights[rows[r]] = refined_row_weight(w.refined[r], first_weights[rows[r]]);
    // The weighted rows, as weighted_frequency_bounds() makes them: the element
    // blocks, the springs' absolute values and the element couplings.
    weighted_rows(system, rows, rows.size(), weights, w, lambda, stiffest_spring);
  }


  void
  gershgorin_row_sums(const ParticleSystem            &system,
                      const double                    *x,
                      const std::vector<unsigned int> &rows,
                      GershgorinRowScratch            &scratch,
                      double                          *row_sum)
  {
    const SpringSet      &springs = system.springs;
    GershgorinRowScratch &w       = scratch;
    gather_row_terms(system, x, rows, w);
    for (std::size_t r = 0; r < rows.size(); ++r)
      row_sum[r] = largest_eigenvalue(w.blocks[r]);
    for (std::size_t k = 0; k < w.springs.size(); ++k)
    {
      const unsigned int s = w.springs[k], i = springs.a[s], j = springs.b[s];
      if (!(system.free[i] > 0 && system.free[j] > 0))
        continue;
      for (const unsigned int p : {i, j})
        if (w.row_stamp[p] == w.stamp)
          row_sum[w.row_of[p]] += w.pair_norm[k];
    }
  }


  std::vector<double>
  squared_frequency_bounds(const ParticleSystem &system, const GershgorinTerms &terms)
  {
    const SpringSet    &springs = system.springs;
    std::vector<double> lambda(system.n_particles(), 0.0);
    for_each_particle_range(system,
                            [&](const unsigned int begin, const unsigned int end)
                            {
                              // lambda first holds the off-diagonal sums.
                              for (std::size_t s = 0; s < springs.size(); ++s)
                                if (terms.coupling[s] > 0)
                                {
                                  const unsigned int i = springs.a[s], j = springs.b[s];
                                  if ((i < begin || i >= end) && (j < begin || j >= end))
                                    continue;
                                  const double c =
                                    terms.coupling[s]
                                    / std::sqrt(system.mass[i] * system.mass[j]);
                                  for (const unsigned int p : {i, j})
                                    if (p >= begin && p < end)
                                      lambda[p] += c;
                                }
                              for (unsigned int i = begin; i < end; ++i)
                                lambda[i] =
                                  has_row(system, i)
                                    ? terms.diagonal[i] / system.mass[i] + lambda[i]
                                    : 0.0;
                            });
    return lambda;
  }


  namespace
  {
    /// What the weighted rows read of one spring (weighted_rows_of_range()).
    struct SpringRowTerms
    {
      /// Its block |K_e|.
      const std::array<double, 6> &absolute;
      /// The bound of ||K_e|| with the force model's off-diagonal norm on its edge.
      double pair_norm;
      /// That off-diagonal norm if both ends are free, 0 otherwise.
      double element_coupling;
    };


    /**
     * The squared rows λ_i of weighted_frequency_bounds() with the row @p factors and
     * @p up factors for the particles i in [@p begin, @p end) into @p lambda, and the
     * first of the springs with the largest pair norm at each into @p stiffest (if not
     * null): one pass over the springs that adds, in spring order, the terms
     * @p spring_terms(s) (a SpringRowTerms) of every spring with an end in the range to
     * that end's row, then the force model's diagonal @p element_block (none if
     * empty).
     */
    template <typename SpringTerms>
    void
    weighted_rows_of_range(const ParticleSystem                     &system,
                           const std::vector<RowFactors>            &factors,
                           const std::vector<double>                &up,
                           const std::vector<std::array<double, 6>> &element_block,
                           const unsigned int                        begin,
                           const unsigned int                        end,
                           const SpringTerms                        &spring_terms,
                           double                                   *lambda,
                           unsigned int                             *stiffest)
    {
      const SpringSet                   &springs = system.springs;
      std::vector<std::array<double, 6>> blocks(end - begin, std::array<double, 6>{});
      std::vector<double>                off_diagonal(end - begin, 0.0);
      std::vector<double>                largest(stiffest ? end - begin : 0, 0.0);
      for (std::size_t s = 0; s < springs.size(); ++s)
      {
        const unsigned int i = springs.a[s], j = springs.b[s];
        const bool         has_i = i >= begin && i < end, has_j = j >= begin && j < end;
        if (!has_i && !has_j)
          continue;
        const SpringRowTerms terms = spring_terms(s);
        for (const auto &[p, q, has_p] :
             {std::tuple{i, j, has_i}, std::tuple{j, i, has_j}})
        {
          if (!has_p)
            continue;
          add_weighted_spring_terms(system,
                                    p,
                                    q,
                                    factors[p],
                                    up[q],
                                    terms.absolute,
                                    terms.element_coupling,
                                    blocks[p - begin],
                                    off_diagonal[p - begin]);
          if (stiffest != nullptr && terms.pair_norm > largest[p - begin])
          {
            largest[p - begin] = terms.pair_norm;
            stiffest[p]        = static_cast<unsigned int>(s);
          }
        }
      }
      const std::array<double, 6> none{};
      for (unsigned int i = begin; i < end; ++i)
        lambda[i] = has_row(system, i)
                      ? row_block_bound(blocks[i - begin],
                                        element_block.empty() ? none : element_block[i])
                            / system.mass[i]
                          + off_diagonal[i - begin]
                      : 0.0;
    }


    /// The RowFactors and up_factor() of every particle with the row @p weights.
    void
    all_row_factors(const ParticleSystem      &system,
                    const std::vector<double> &weights,
                    std::vector<RowFactors>   &factors,
                    std::vector<double>       &up)
    {
      factors.resize(system.n_particles());
      up.resize(system.n_particles());
      for_each_particle_range(system,
                              [&](const unsigned int begin, const unsigned int end)
                              {
                                for (unsigned int i = begin; i < end; ++i)
                                {
                                  factors[i] = row_factors(system, weights, i);
                                  up[i]      = up_factor(system, weights, i);
                                }
                              });
    }
  } // namespace


  std::vector<double>
  weighted_frequency_bounds(const ParticleSystem      &system,
                            const GershgorinTerms     &terms,
                            const std::vector<double> &weights)
  {
    std::vector<RowFactors> factors;
    std::vector<double>     up;
    // Every row reads the up factors of its neighbours in other ranges: all are set
    // before the first row adds its springs.
    all_row_factors(system, weights, factors, up);
    std::vector<double> lambda(system.n_particles(), 0.0);
    for_each_particle_range(
      system,
      [&](const unsigned int begin, const unsigned int end)
      {
        weighted_rows_of_range(
          system,
          factors,
          up,
          terms.element_block,
          begin,
          end,
          [&](const std::size_t s) {
            return SpringRowTerms{terms.spring_block[s], 0.0, terms.element_coupling[s]};
          },
          lambda.data(),
          nullptr);
      });
    return lambda;
  }


  std::vector<double>
  weighted_frequency_bounds_at(const ParticleSystem      &system,
                               const double              *x,
                               const std::vector<double> &weights,
                               std::vector<unsigned int> &stiffest_spring)
  {
    const unsigned int n       = system.n_particles();
    const SpringSet   &springs = system.springs;
    const double       scale   = spring_scale(system);
    // The force model's element terms, as gershgorin_terms() adds them (arrays only if
    // the model has elements).
    std::vector<std::array<double, 6>> element_block;
    std::vector<double>                element_norm;
    if (system.has_force_model())
      system.force_model().for_each_element_stiffness(
        system,
        x,
        [&](const unsigned int t, const ForceModel::ElementStiffness &K)
        {
          if (element_block.empty())
          {
            element_block.assign(n, std::array<double, 6>{});
            element_norm.assign(springs.size(), 0.0);
          }
          const mesh::Tet &tet = system.mesh->tet(t);
          element_terms(
            K,
            [&](unsigned int a, const std::array<double, 6> &b)
            { add_block(element_block[tet[a]], b); },
            [&](unsigned int e, double norm)
            { element_norm[system.mesh->tet_edges(t)[e]] += norm; });
        });
    std::vector<RowFactors> factors;
    std::vector<double>     up;
    all_row_factors(system, weights, factors, up);
    std::vector<double> lambda(n, 0.0);
    stiffest_spring.assign(n, 0);
    for_each_particle_range(
      system,
      [&](const unsigned int begin, const unsigned int end)
      {
        // Each range works out the terms of its springs itself: a spring between two
        // ranges twice, to the same bits.
        std::array<double, 6> absolute;
        weighted_rows_of_range(
          system,
          factors,
          up,
          element_block,
          begin,
          end,
          [&](const std::size_t s)
          {
            double norm = 0;
            spring_tangent_block(springs, s, x, scale, norm, absolute);
            double       element   = element_norm.empty() ? 0.0 : element_norm[s];
            const double pair_norm = norm + element;
            if (!(system.free[springs.a[s]] > 0 && system.free[springs.b[s]] > 0))
              element = 0;
            return SpringRowTerms{absolute, pair_norm, element};
          },
          lambda.data(),
          stiffest_spring.data());
      });
    return lambda;
  }


  std::vector<double>
  isotropic_frequency_bounds(const ParticleSystem      &system,
                             const std::vector<double> &weights)
  {
    if (system.has_force_model() && system.force_model().has_element_stiffness())
      throw_error("isotropic_frequency_bounds() bounds a force model of springs only.");
    const unsigned int      n       = system.n_particles();
    const SpringSet        &springs = system.springs;
    const double            scale   = spring_scale(system);
    std::vector<RowFactors> factors;
    std::vector<double>     up;
    all_row_factors(system, weights, factors, up);
    // Row i of weighted_rows(): λ_max(Σ_e (1 + t_e) |K_e|) / m_i, with |K_e| at most
    // |k_e| times the identity wherever the spring is at least half its rest length.
    std::vector<double> row(n, 0.0);
    for (std::size_t s = 0; s < springs.size(); ++s)
    {
      const unsigned int i = springs.a[s], j = springs.b[s];
      const double       k       = std::abs(scale * springs.stiffness[s]);
      const bool         coupled = system.free[i] > 0 && system.free[j] > 0;
      row[i] += (1 + (coupled ? factors[i].down * up[j] : 0.0)) * k;
      row[j] += (1 + (coupled ? factors[j].down * up[i] : 0.0)) * k;
    }
    for (unsigned int i = 0; i < n; ++i)
      row[i] = has_row(system, i) ? row[i] / system.mass[i] : 0.0;
    return row;
  }


  std::vector<double>
  spring_motion_allowances(const ParticleSystem      &system,
                           const double              *reference,
                           const std::vector<double> &reference_rows,
                           const std::vector<double> &isotropic,
                           const double               squared_omega)
  {
    const SpringSet &springs = system.springs;
    // How far row p's springs may turn and stretch, relative to their length at the
    // reference, before its row can exceed the limit: the row rises by at most
    // 4 ρ times its isotropic bound when no spring's ends moved by more than ρ of its
    // reference length (doc/stability.md). A row the isotropic bound settles allows
    // any motion; a row at or above the limit none.
    const auto allowance = [&](const unsigned int p)
    {
      if (isotropic[p] <= squared_omega)
        return std::numeric_limits<double>::infinity();
      const double a = (squared_omega - reference_rows[p]) / (4 * isotropic[p]);
      return a > 0 ? a : -1.0;
    };
    std::vector<double> allowed(springs.size());
    for (std::size_t s = 0; s < springs.size(); ++s)
    {
      const unsigned int i = springs.a[s], j = springs.b[s];
      const double       rho = std::min(allowance(i), allowance(j));
      if (rho < 0)
      {
        allowed[s] = -1;
        continue;
      }
      if (std::isinf(rho))
      {
        allowed[s] = rho;
        continue;
      }
      double squared_length = 0;
      for (unsigned int d = 0; d < 3; ++d)
      {
        const double c = reference[3 * j + d] - reference[3 * i + d];
        squared_length += c * c;
      }
      allowed[s] = rho * rho * squared_length;
    }
    return allowed;
  }


  void
  append_ends_of_springs_to_bound_again(const ParticleSystem      &system,
                                        const double              *x,
                                        const double              *reference,
                                        const std::vector<double> &allowed,
                                        std::vector<unsigned int> &ends)
  {
    const SpringSet &springs = system.springs;
    for (std::size_t s = 0; s < springs.size(); ++s)
    {
      const unsigned int i = springs.a[s], j = springs.b[s];
      double             now[3], length      = 0;
      for (unsigned int d = 0; d < 3; ++d)
      {
        now[d] = x[3 * j + d] - x[3 * i + d];
        length += now[d] * now[d];
      }
      const double half = 0.5 * springs.rest_length[s];
      // Written so that a length that is not a number is bounded again. A spring
      // whose rows allow any motion needs no reference.
      bool again = !(length >= half * half);
      if (!again && !std::isinf(allowed[s]))
      {
        double moved = 0;
        for (unsigned int d = 0; d < 3; ++d)
        {
          const double c = now[d] - (reference[3 * j + d] - reference[3 * i + d]);
          moved += c * c;
        }
        again = !(moved <= allowed[s]);
      }
      if (again)
      {
        ends.push_back(i);
        ends.push_back(j);
      }
    }
  }


  std::vector<double>
  gershgorin_row_weights(const ParticleSystem &system, const GershgorinTerms &terms)
  {
    std::vector<double> weights = squared_frequency_bounds(system, terms);
    for (double &w : weights)
      w = gershgorin_row_weight(w);
    return weights;
  }


  std::vector<double>
  refined_row_weights(const ParticleSystem      &system,
                      const GershgorinTerms     &terms,
                      const std::vector<double> &weights)
  {
    std::vector<double> refined = weighted_frequency_bounds(system, terms, weights);
    for (unsigned int i = 0; i < refined.size(); ++i)
      refined[i] = refined_row_weight(refined[i], weights[i]);
    return refined;
  }


  std::vector<double>
  particle_frequency_bounds(const ParticleSystem &system)
  {
    std::vector<double> omega =
      squared_frequency_bounds(system, gershgorin_terms(system, system.position.data()));
    for (double &w : omega)
      w = std::sqrt(w);
    return omega;
  }


  FrequencyBound
  bound_highest_frequency(const ParticleSystem &system)
  {
    const GershgorinTerms     terms  = gershgorin_terms(system, system.position.data());
    const std::vector<double> lambda = weighted_frequency_bounds(
      system,
      terms,
      refined_row_weights(system, terms, gershgorin_row_weights(system, terms)));
    FrequencyBound bound;
    double         largest = 0;
    for (unsigned int i = 0; i < lambda.size(); ++i)
      if (lambda[i] > largest)
      {
        largest        = lambda[i];
        bound.particle = i;
        bound.spring   = terms.stiffest_spring[i];
      }
    bound.omega = std::sqrt(largest);
    return bound;
  }


  double
  multirate_evaluation_share(const ParticleSystem &system)
  {
    const std::vector<double> omega   = particle_frequency_bounds(system);
    const double              highest = *std::max_element(omega.begin(), omega.end());
    if (system.springs.size() == 0 || !(highest > 0))
      return 1;
    double evaluations = 0;
    for (std::size_t s = 0; s < system.springs.size(); ++s)
    {
      const double fastest =
        std::max(omega[system.springs.a[s]], omega[system.springs.b[s]]);
      // A spring steps at the single-rate step times the largest power of two that
      // keeps ω h below the bound at both its particles (ω h scales as 1/ω).
      double step = 1;
      // Ties (a regular mesh's boundary has particles at exactly half the frequency)
      // count as allowed whatever the rounding, so the share is the same on every
      // compiler.
      while (fastest > 0 && 2 * step * fastest <= highest * (1 + 1e-9) && step < 1024)
        step *= 2;
      if (fastest == 0)
        step = 1024;
      evaluations += 1 / step;
    }
    return evaluations / system.springs.size();
  }


  std::string
  describe_spring(const ParticleSystem &system, const unsigned int s)
  {
    const SpringSet   &springs = system.springs;
    const double      *x       = system.position.data();
    const unsigned int i = springs.a[s], j = springs.b[s];
    std::ostringstream text;
    text.precision(6);
    text << "spring " << s << " between " << describe_particle(system, i) << " and "
         << describe_particle(system, j) << ", stiffness " << springs.stiffness[s]
         << " N/m, rest length " << springs.rest_length[s] << " m, length "
         << std::hypot(x[3 * j] - x[3 * i],
                       x[3 * j + 1] - x[3 * i + 1],
                       x[3 * j + 2] - x[3 * i + 2])
         << " m";
    return text.str();
  }


  BlowUpMonitor::BlowUpMonitor(const ParticleSystem &system, const double tolerance)
      : tolerance(tolerance)
      , energy_scale(system.kinetic_energy() + system.elastic_energy())
      , energy_floor(noise_energy(system))
  {
    start_ledger(system);
  }


  void
  BlowUpMonitor::start_ledger(const ParticleSystem &system)
  {
    initial_energy =
      system.kinetic_energy() + system.elastic_energy() + system.body_force_energy();
    work              = 0;
    previous_position = system.position;
    load.assign(system.position.size(), 0.0);
    compute_load_forces(system);
    previous_load = load;
  }


  void
  BlowUpMonitor::compute_load_forces(const ParticleSystem &system)
  {
    // Prescribed particles push with the reaction to the spring forces on them;
    // free particles receive the external forces.
    system.force_model().compute_spring_forces(system,
                                               system.position.data(),
                                               system.velocity.data(),
                                               load.data());
    for (unsigned int i = 0; i < system.n_particles(); ++i)
      for (unsigned int d = 0; d < 3; ++d)
        load[3 * i + d] =
          system.free[i] > 0 ? system.external_force[3 * i + d] : -load[3 * i + d];
  }


  void
  BlowUpMonitor::check_finite(const ParticleSystem            &system,
                              const std::vector<unsigned int> *particles,
                              const unsigned int               step,
                              const double                     time,
                              const std::string               &after) const
  {
    const auto check = [&](const unsigned int i)
    {
      for (unsigned int d = 0; d < 3; ++d)
        if (!std::isfinite(system.position[3 * i + d])
            || !std::isfinite(system.velocity[3 * i + d]))
          throw_error("The simulation blew up at step ",
                      step,
                      ", time ",
                      time,
                      " s",
                      after,
                      ": ",
                      describe_particle(system, i),
                      " has a position or velocity that is not a finite number. Reduce "
                      "'Time step' or raise 'Stability/Safety factor' margin.");
    };
    if (particles != nullptr)
      for (const unsigned int i : *particles)
        check(i);
    else
      for (unsigned int i = 0; i < system.n_particles(); ++i)
        check(i);
  }


  double
  BlowUpMonitor::check_energy(const ParticleSystem &system,
                              const unsigned int    step,
                              const double          time,
                              const std::string    &after) const
  {
    const double kinetic = system.kinetic_energy();
    const double elastic = system.elastic_energy();
    const double body    = system.body_force_energy();
    const double energy  = kinetic + elastic + body;
    const double excess  = energy - initial_energy - work;
    // The scale: the largest energy of the states already accepted, or the energy the
    // system may have now, not the energy under test.
    const double scale =
      std::max(energy_scale, std::abs(initial_energy) + std::abs(work));
    // Written so that a NaN energy (an infinite spring force) also stops the run.
    if (!(excess <= tolerance * scale + energy_floor || excess <= energy_floor))
    {
      unsigned int fastest = 0;
      double       speed   = 0;
      for (unsigned int i = 0; i < system.n_particles(); ++i)
      {
        const double *v = &system.velocity[3 * i];
        const double  s = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
        if (s > speed)
        {
          speed   = s;
          fastest = i;
        }
      }
      throw_error("The simulation blew up at step ",
                  step,
                  ", time ",
                  time,
                  " s",
                  after,
                  ": the mechanical energy (",
                  energy,
                  " J) exceeds the initial energy plus the work of the loads (",
                  initial_energy + work,
                  " J) by ",
                  excess,
                  " J, more than 'Energy growth tolerance' allows. The fastest is ",
                  describe_particle(system, fastest),
                  " at ",
                  speed,
                  " m/s. Reduce 'Time step' or add damping.");
    }
    return kinetic + elastic + std::abs(body);
  }


  void
  BlowUpMonitor::check(const ParticleSystem &system,
                       const unsigned int    step,
                       const double          time)
  {
    const std::string after =
      pending_change.empty() ? std::string() : " (since " + pending_change + ")";
    check_finite(system, nullptr, step, time, after);

    compute_load_forces(system);
    const std::vector<double> &x = system.position;
    for (std::size_t c = 0; c < x.size(); ++c)
      work += 0.5 * (previous_load[c] + load[c]) * (x[c] - previous_position[c]);
    previous_position = x;
    previous_load     = load;

    // The scale is the largest energy of the states already accepted: had it included
    // the state under test, the excess could never exceed it with a tolerance of 1
    // (the default), and a run reached 1e127 J unstopped.
    energy_scale =
      std::max(energy_scale, check_energy(system, step, time, after) + std::abs(work));
    if (!pending_change.empty())
    {
      // The rest of restart() for the local changes since the last check: the ledger
      // starts again from this state (see restart()).
      energy_floor = std::max(energy_floor, noise_energy(system));
      start_ledger(system);
      pending_change.clear();
    }
  }


  void
  BlowUpMonitor::note_local_change(const ParticleSystem            &system,
                                   const std::vector<unsigned int> &changed,
                                   const unsigned int               step,
                                   const double                     time,
                                   const std::string               &cause)
  {
    check_finite(system, &changed, step, time, " (right after " + cause + ")");
    // New particles enter the work of the loads from where they are now.
    // Particles removed from the end (a coarser level of detail) leave it; a moved one
    // takes the slot's entries until the ledger restarts at the next check.
    const std::size_t n = system.position.size();
    for (std::size_t c = previous_position.size(); c < n; ++c)
      previous_position.push_back(system.position[c]);
    previous_position.resize(n);
    previous_load.resize(n, 0.0);
    load.resize(n, 0.0);
    if (pending_change.empty())
    {
      std::ostringstream what;
      what << cause << " at step " << step << ", time " << time << " s";
      pending_change = what.str();
    }
  }


  void
  BlowUpMonitor::restart(const ParticleSystem &system,
                         const unsigned int    step,
                         const double          time,
                         const std::string    &cause)
  {
    const std::string after = " (right after " + cause + ")";
    pending_change.clear();
    check_finite(system, nullptr, step, time, after);
    energy_floor = std::max(energy_floor, noise_energy(system));
    energy_scale = std::max(energy_scale, check_energy(system, step, time, after));
    // The ledger starts again from the new state: the work of the loads since the
    // last check is lost with the old particles, and carrying an excess over many
    // changes (a stroke changes the system at every step) accumulated that loss into
    // false alarms.
    start_ledger(system);
  }


  void
  BlowUpMonitor::serialize(Archive &archive)
  {
    archive.section("blow-up monitor");
    archive(pending_change, tolerance, initial_energy, energy_scale, energy_floor, work);
    archive(previous_position, previous_load, load);
  }
} // namespace lacerta::physics
