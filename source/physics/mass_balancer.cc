#include <lacerta/physics/mass_balancer.h>
#include <lacerta/physics/particle_system.h>
#include <lacerta/physics/stability.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

namespace lacerta::physics
{
  namespace
  {
    /// The springs at each particle, as (neighbour, spring) in compressed rows.
    struct Neighbours
    {
      std::vector<unsigned int> offset, particle, spring;

      explicit Neighbours(const ParticleSystem &system)
          : offset(system.n_particles() + 1, 0)
      {
        const SpringSet &springs = system.springs;
        for (std::size_t s = 0; s < springs.size(); ++s)
        {
          ++offset[springs.a[s] + 1];
          ++offset[springs.b[s] + 1];
        }
        for (std::size_t i = 1; i < offset.size(); ++i)
          offset[i] += offset[i - 1];
        particle.resize(offset.back());
        spring.resize(offset.back());
        std::vector<unsigned int> next(offset.begin(), offset.end() - 1);
        for (unsigned int s = 0; s < springs.size(); ++s)
        {
          const unsigned int a = springs.a[s], b = springs.b[s];
          particle[next[a]] = b;
          spring[next[a]++] = s;
          particle[next[b]] = a;
          spring[next[b]++] = s;
        }
      }
    };


    /**
     * The row sums of the block Gershgorin bound of M⁻¹K at rest, a_i + Σ_e c_e over
     * the springs at i (gershgorin_terms()): the bound at particle i is that over m_i,
     * whatever its neighbours weigh, so the mass a particle needs is its row sum over
     * the target.
     */
    class RestBound
    {
    public:
      RestBound(const ParticleSystem &system)
          : system(system)
          , neighbours(system)
      {
        const GershgorinTerms terms =
          gershgorin_terms(system, system.rest_position().data());
        row = terms.diagonal;
        for (std::size_t s = 0; s < system.springs.size(); ++s)
        {
          row[system.springs.a[s]] += terms.coupling[s];
          row[system.springs.b[s]] += terms.coupling[s];
        }
      }

      /// The bound λ_i (infinite for a mass that is not positive).
      double
      lambda(const unsigned int i) const
      {
        const double m = system.mass[i];
        return m > 0 ? row[i] / m : std::numeric_limits<double>::infinity();
      }

      /// The mass at which λ_i equals @p target.
      double
      needed(const unsigned int i, const double target) const
      {
        return row[i] / target;
      }

      const ParticleSystem &system;
      const Neighbours      neighbours;
      std::vector<double>   row;
    };


    /**
     * Raises particle @p i's mass by @p need, taking it from the free particles within
     * @p reach springs, ring by ring: a ring that has enough gives in proportion to
     * what each of its particles can spare (half of what it has above the mass that
     * keeps its own bound at @p limit); otherwise it gives all it can and the next ring
     * is asked. All or nothing: when the particles within reach cannot spare @p need
     * together, nothing moves (mass that leaves the particle above the target does not
     * lower the largest bound, and only changes the dynamics). Returns the mass moved.
     */
    double
    borrow(ParticleSystem      &system,
           const RestBound     &bound,
           const unsigned int   i,
           const double         need,
           const double         limit,
           const unsigned int   reach,
           std::vector<char>   &seen,
           std::vector<double> &spare)
    {
      // The donors, ring by ring (ring r starts at first[r]), and what each can spare.
      std::vector<unsigned int> donors, first = {0};
      std::vector<unsigned int> ring = {i};
      seen[i]                        = 1;
      double available               = 0;
      for (unsigned int hop = 0; hop < reach && available < need && !ring.empty(); ++hop)
      {
        for (const unsigned int p : ring)
          for (unsigned int k = bound.neighbours.offset[p];
               k < bound.neighbours.offset[p + 1];
               ++k)
          {
            const unsigned int j = bound.neighbours.particle[k];
            if (seen[j] || !(system.free[j] > 0))
              continue;
            seen[j] = 1;
            spare[donors.size()] =
              std::max(0.0, 0.5 * (system.mass[j] - bound.needed(j, limit)));
            available += spare[donors.size()];
            donors.push_back(j);
          }
        ring.assign(donors.begin() + first.back(), donors.end());
        first.push_back(donors.size());
      }
      seen[i] = 0;
      for (const unsigned int p : donors)
        seen[p] = 0;
      if (available < need)
        return 0;

      double left = need;
      for (std::size_t r = 0; r + 1 < first.size() && left > 0; ++r)
      {
        double in_ring = 0;
        for (unsigned int d = first[r]; d < first[r + 1]; ++d)
          in_ring += spare[d];
        const double fraction = in_ring > left ? left / in_ring : 1.0;
        for (unsigned int d = first[r]; d < first[r + 1]; ++d)
        {
          const double given = fraction * spare[d];
          system.mass[donors[d]] -= given;
          system.mass[i] += given;
        }
        left -= fraction * in_ring;
      }
      return need - std::max(0.0, left);
    }
  } // namespace


  MassBalancer::MassBalancer(const ParticleSystem &system, const unsigned int reach)
      : target_lambda(0)
      , reach(std::max(1u, reach))
  {
    const RestBound bound(system);
    for (unsigned int i = 0; i < system.n_particles(); ++i)
      if (system.free[i] > 0)
        target_lambda = std::max(target_lambda, bound.lambda(i));
  }


  MassBalanceStatistics
  MassBalancer::balance(ParticleSystem &system) const
  {
    MassBalanceStatistics statistics;
    if (!(target_lambda > 0) || !std::isfinite(target_lambda))
      return statistics;
    const unsigned int        n      = system.n_particles();
    const std::vector<double> before = system.mass;
    // From the lumped masses every time: the result depends on the mesh, not on the
    // changes that led to it, and a particle that gave mass and lost cells since is
    // not left with too little.
    system.mass_shift.resize(n, 0.0);
    for (unsigned int i = 0; i < n; ++i)
      system.mass[i] -= system.mass_shift[i];
    const std::vector<double> lumped = system.mass;
    const RestBound           bound(system);
    std::vector<char>         seen(n, 0);
    std::vector<double>       spare(n);
    // The bound is itself computed in floating point: a particle just above a limit is
    // left alone.
    const double tolerance = 1 + 1e-9;
    const double limit     = donor_headroom * target_lambda;
    // A particle's need does not depend on its neighbours' masses: one pass, in the
    // order of the particles, raises every particle above the target (a donor never
    // falls below the mass that keeps it at the donors' limit).
    for (unsigned int i = 0; i < n; ++i)
    {
      if (!(system.free[i] > 0) || !(bound.lambda(i) > tolerance * target_lambda))
        continue;
      // Aim a little below the target so that rounding leaves nothing to do.
      const double need  = bound.needed(i, target_lambda / (1 + 1e-6)) - system.mass[i];
      const double moved = borrow(system, bound, i, need, limit, reach, seen, spare);
      statistics.moved += moved;
      statistics.raised += moved > 0;
    }
    std::vector<unsigned int> changed;
    for (unsigned int i = 0; i < n; ++i)
    {
      statistics.unresolved += system.free[i] > 0 && bound.lambda(i) > tolerance * limit;
      system.mass_shift[i] = system.mass[i] - lumped[i];
      if (system.mass[i] != before[i])
        changed.push_back(i);
    }
    if (!changed.empty())
      system.masses_changed(changed);
    return statistics;
  }
} // namespace lacerta::physics
