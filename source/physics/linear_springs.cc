// Force model `linear springs`: the paper's springs, f = k (|d| - L0) d/|d|.

#include <lacerta/physics/force_model.h>
#include <lacerta/physics/particle_system.h>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/partitioner.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>

namespace lacerta::physics
{
  namespace
  {
    /**
     * Adds the forces of springs [begin, end) to f. Spring s pulls a[s] towards b[s]
     * with k (L - L0) (plus β k (dv·n) along the spring if Damped). If BothEnds is
     * false only the end a[s] is written: the spring crosses into another thread's
     * particles, which computes it too and writes its own end.
     */
    template <bool Damped, bool BothEnds>
    inline void
    add_spring_forces(const SpringSet  &springs,
                      const std::size_t begin,
                      const std::size_t end,
                      const double     *x,
                      const double     *v,
                      const double      beta,
                      double           *f)
    {
      const unsigned int *__restrict a = springs.a.data();
      const unsigned int *__restrict b = springs.b.data();
      const double *__restrict k       = springs.stiffness.data();
      const double *__restrict l0      = springs.rest_length.data();
      for (std::size_t s = begin; s < end; ++s)
      {
        const unsigned int i         = 3 * a[s];
        const unsigned int j         = 3 * b[s];
        const double       dx        = x[j] - x[i];
        const double       dy        = x[j + 1] - x[i + 1];
        const double       dz        = x[j + 2] - x[i + 2];
        const double       len       = std::sqrt(dx * dx + dy * dy + dz * dz);
        const double       inv       = 1.0 / len;
        double             magnitude = k[s] * (len - l0[s]);
        if constexpr (Damped)
          magnitude += beta * k[s] * inv
                       * ((v[j] - v[i]) * dx + (v[j + 1] - v[i + 1]) * dy
                          + (v[j + 2] - v[i + 2]) * dz);
        const double scale = magnitude * inv;
        f[i] += scale * dx;
        f[i + 1] += scale * dy;
        f[i + 2] += scale * dz;
        if constexpr (BothEnds)
        {
          f[j] -= scale * dx;
          f[j + 1] -= scale * dy;
          f[j + 2] -= scale * dz;
        }
      }
    }


    /**
     * The paper's spring model with a flat, thread-partitioned spring loop.
     *
     * Particles are split into one contiguous range per thread (the mesh is numbered
     * along a space-filling curve, so a range is a compact region). A thread owns the
     * forces of its range: it evaluates the springs inside its range (writing both
     * ends) and the springs that cross into another range (writing only its own end).
     * Crossing springs are thus evaluated twice, but no thread ever writes another's
     * memory: no atomics, no locks, no reduction.
     *
     * Each range's inner and crossing springs are a segment of their own, kept in the
     * order of the system's springs, and every system spring knows which segments hold
     * its copies, so that a cut updates only the springs it changed (springs_changed()):
     * a copy whose segment stays is rewritten in place (found by bisection), one that
     * changes range is moved, removed springs are the last ones. The evaluation then
     * sums every particle's forces in the order a model made afresh on the same ranges
     * would: on one range the forces are those of initialize() to the last bit. New
     * particles join the last range; when the ranges' loads drift apart by more than a
     * quarter of the mean, the partition is made again.
     */
    class LinearSprings : public ForceModel
    {
    public:
      static void
      declare_parameters(dealii::ParameterHandler &)
      {
      }

      void
      initialize(const ParticleSystem &system, const unsigned int n_threads) override
      {
        threads              = n_threads;
        const unsigned int n = system.n_particles();
        const unsigned int n_parts =
          std::max(1u, std::min(n_threads, std::max(1u, n / 64)));

        // Balance the ranges by the number of spring ends they hold.
        std::vector<std::size_t> ends(n + 1, 0);
        for (std::size_t s = 0; s < system.springs.size(); ++s)
        {
          ++ends[system.springs.a[s] + 1];
          ++ends[system.springs.b[s] + 1];
        }
        for (unsigned int i = 0; i < n; ++i)
          ends[i + 1] += ends[i];
        first_particle.assign(n_parts + 1, n);
        first_particle[0] = 0;
        for (unsigned int p = 1; p < n_parts; ++p)
          first_particle[p] =
            std::lower_bound(ends.begin(), ends.end(), ends[n] * p / n_parts)
            - ends.begin();

        segments.assign(2 * n_parts, Segment());
        holders.assign(system.springs.size(), no_holders());
        for (unsigned int s = 0; s < system.springs.size(); ++s)
          place(system, s);
        known_springs = system.springs.size();

        inverse_mass.resize(n);
        for (unsigned int i = 0; i < n; ++i)
          inverse_mass[i] = system.mass[i] > 0 ? 1.0 / system.mass[i] : 0.0;
        arena = std::make_unique<tbb::task_arena>(static_cast<int>(n_parts));
      }

      void
      springs_changed(const ParticleSystem            &system,
                      const std::vector<unsigned int> &changed) override
      {
        const std::size_t  n_springs = system.springs.size();
        const unsigned int n         = system.n_particles();
        // New particles join the last range.
        first_particle.back()           = n;
        const std::size_t old_particles = inverse_mass.size();
        inverse_mass.resize(n);
        for (std::size_t i = old_particles; i < n; ++i)
          update_inverse_mass(system, i);

        // The listed springs once each, removed ones first and from the end (their
        // copies are the last of their segments), then the others in order (appended
        // ones go to the ends of their segments). A listed spring may have been
        // appended and removed again since (beyond both counts): it has no copies.
        std::vector<unsigned int> listed;
        listed.reserve(changed.size() + known_springs
                       - std::min(known_springs, n_springs));
        for (const unsigned int s : changed)
          if (s < std::max(known_springs, n_springs))
            listed.push_back(s);
        for (std::size_t s = n_springs; s < known_springs; ++s)
          listed.push_back(static_cast<unsigned int>(s));
        std::sort(listed.begin(), listed.end());
        listed.erase(std::unique(listed.begin(), listed.end()), listed.end());
        holders.resize(std::max(known_springs, n_springs), no_holders());
        for (auto s = listed.rbegin(); s != listed.rend() && *s >= n_springs; ++s)
          unplace(*s);
        for (const unsigned int s : listed)
          if (s < n_springs)
          {
            place(system, s);
            update_inverse_mass(system, system.springs.a[s]);
            update_inverse_mass(system, system.springs.b[s]);
          }
        holders.resize(n_springs);
        known_springs = n_springs;

        if (unbalanced())
          initialize(system, threads);
      }

      void
      masses_changed(const ParticleSystem            &system,
                     const std::vector<unsigned int> &particles) override
      {
        for (const unsigned int i : particles)
          update_inverse_mass(system, i);
      }

      void
      compute_acceleration(const ParticleSystem &system,
                           const double         *x,
                           const double         *v,
                           double               *a) const override
      {
        for_each_part(
          [&](const unsigned int p)
          {
            spring_forces_of_part(system, p, x, v, a);
            const double *g   = system.body_acceleration.data();
            const double  c   = system.mass_damping;
            const double *ext = system.external_force.data();
            for (unsigned int i = first_particle[p]; i < first_particle[p + 1]; ++i)
            {
              const double m_inv = inverse_mass[i];
              const double keep  = system.free[i];
              for (unsigned int d = 0; d < 3; ++d)
                a[3 * i + d] =
                  keep
                  * ((a[3 * i + d] + ext[3 * i + d]) * m_inv + g[d] - c * v[3 * i + d]);
            }
          });
      }

      void
      compute_spring_forces(const ParticleSystem &system,
                            const double         *x,
                            const double         *v,
                            double               *f) const override
      {
        for_each_part([&](const unsigned int p)
                      { spring_forces_of_part(system, p, x, v, f); });
      }

      double
      elastic_energy(const ParticleSystem &system, const double *x) const override
      {
        const SpringSet &all    = system.springs;
        double           energy = 0;
        for (std::size_t s = 0; s < all.size(); ++s)
        {
          const unsigned int i = 3 * all.a[s], j = 3 * all.b[s];
          const double       len =
            std::hypot(x[j] - x[i], x[j + 1] - x[i + 1], x[j + 2] - x[i + 2]);
          energy += 0.5 * all.stiffness[s] * (len - all.rest_length[s])
                    * (len - all.rest_length[s]);
        }
        return energy;
      }

    private:
      /// The springs of one range: inner (both ends in it) or crossing (end a in it).
      struct Segment
      {
        SpringSet set;
        /// The system spring of each entry.
        std::vector<unsigned int> origin;
      };

      /// The segments that hold a system spring's copies (up to two).
      using Holders = std::array<unsigned int, 2>;

      static constexpr unsigned int none = static_cast<unsigned int>(-1);

      static Holders
      no_holders()
      {
        return {none, none};
      }

      /// The range of particle @p i.
      unsigned int
      part_of(const unsigned int i) const
      {
        return static_cast<unsigned int>(
          std::upper_bound(first_particle.begin() + 1, first_particle.end() - 1, i)
          - first_particle.begin() - 1);
      }

      void
      update_inverse_mass(const ParticleSystem &system, const std::size_t i)
      {
        inverse_mass[i] = system.mass[i] > 0 ? 1.0 / system.mass[i] : 0.0;
      }

      /// Where spring @p s is, or goes, in segment @p g (kept in the springs' order).
      std::size_t
      slot(const unsigned int g, const unsigned int s) const
      {
        const std::vector<unsigned int> &origin = segments[g].origin;
        return std::lower_bound(origin.begin(), origin.end(), s) - origin.begin();
      }

      /// Removes spring @p s's copy from segment @p g.
      void
      erase(const unsigned int g, const unsigned int s)
      {
        Segment          &segment = segments[g];
        const std::size_t k       = slot(g, s);
        segment.set.a.erase(segment.set.a.begin() + k);
        segment.set.b.erase(segment.set.b.begin() + k);
        segment.set.stiffness.erase(segment.set.stiffness.begin() + k);
        segment.set.rest_length.erase(segment.set.rest_length.begin() + k);
        segment.origin.erase(segment.origin.begin() + k);
      }

      /// Removes every copy of spring @p s.
      void
      unplace(const unsigned int s)
      {
        for (const unsigned int g : holders[s])
          if (g != none)
            erase(g, s);
        holders[s] = no_holders();
      }

      /**
       * Puts system spring @p s (as it is now) into the segments of its ranges: in
       * place where it already has a copy in that segment, in order otherwise; copies
       * in segments it left are removed.
       */
      void
      place(const ParticleSystem &system, const unsigned int s)
      {
        const SpringSet   &all = system.springs;
        const unsigned int a = all.a[s], b = all.b[s];
        const unsigned int pa = part_of(a), pb = part_of(b);
        // (segment, first end, second end) of each copy.
        std::array<std::array<unsigned int, 3>, 2> wanted = {
          {{2 * pa, a, b}, {none, 0, 0}}};
        if (pa != pb)
          wanted = {{{2 * pa + 1, a, b}, {2 * pb + 1, b, a}}};
        for (const unsigned int g : holders[s])
          if (g != none && g != wanted[0][0] && g != wanted[1][0])
            erase(g, s);
        const Holders old = holders[s];
        holders[s]        = no_holders();
        for (unsigned int c = 0; c < 2; ++c)
        {
          const auto [g, from, to] = wanted[c];
          if (g == none)
            continue;
          holders[s][c]             = g;
          Segment          &segment = segments[g];
          const std::size_t k       = slot(g, s);
          if (g == old[0] || g == old[1])
          {
            segment.set.a[k]           = from;
            segment.set.b[k]           = to;
            segment.set.stiffness[k]   = all.stiffness[s];
            segment.set.rest_length[k] = all.rest_length[s];
            continue;
          }
          segment.set.a.insert(segment.set.a.begin() + k, from);
          segment.set.b.insert(segment.set.b.begin() + k, to);
          segment.set.stiffness.insert(segment.set.stiffness.begin() + k,
                                       all.stiffness[s]);
          segment.set.rest_length.insert(segment.set.rest_length.begin() + k,
                                         all.rest_length[s]);
          segment.origin.insert(segment.origin.begin() + k, s);
        }
      }

      /// Whether a range evaluates more than 1.25 times the mean number of spring
      /// copies (plus a little, so that small systems are not re-partitioned).
      bool
      unbalanced() const
      {
        const std::size_t n_parts = first_particle.size() - 1;
        if (n_parts == 1)
          return false;
        std::size_t total = 0, largest = 0;
        for (std::size_t p = 0; p < n_parts; ++p)
        {
          const std::size_t load =
            segments[2 * p].origin.size() + segments[2 * p + 1].origin.size();
          total += load;
          largest = std::max(largest, load);
        }
        return largest > 1.25 * total / n_parts + 256;
      }

      /// Zeroes the forces of part @p p's particles and adds its springs' forces.
      void
      spring_forces_of_part(const ParticleSystem &system,
                            const unsigned int    p,
                            const double         *x,
                            const double         *v,
                            double               *f) const
      {
        std::memset(f + 3 * first_particle[p],
                    0,
                    3 * sizeof(double) * (first_particle[p + 1] - first_particle[p]));
        const double     beta     = system.spring_damping;
        const SpringSet &inner    = segments[2 * p].set;
        const SpringSet &crossing = segments[2 * p + 1].set;
        if (beta > 0)
        {
          add_spring_forces<true, true>(inner, 0, inner.size(), x, v, beta, f);
          add_spring_forces<true, false>(crossing, 0, crossing.size(), x, v, beta, f);
        }
        else
        {
          add_spring_forces<false, true>(inner, 0, inner.size(), x, v, beta, f);
          add_spring_forces<false, false>(crossing, 0, crossing.size(), x, v, beta, f);
        }
      }

      /// Runs @p work(p) for every part, in parallel if there is more than one.
      template <typename Work>
      void
      for_each_part(const Work &work) const
      {
        const unsigned int n_parts = first_particle.size() - 1;
        if (n_parts == 1)
        {
          work(0);
          return;
        }
        arena->execute(
          [&]
          {
            tbb::parallel_for(
              tbb::blocked_range<unsigned int>(0, n_parts, 1),
              [&](const tbb::blocked_range<unsigned int> &range)
              {
                for (unsigned int p = range.begin(); p < range.end(); ++p)
                  work(p);
              },
              tbb::static_partitioner());
          });
      }

      /// Inner and crossing springs of range p: segments 2p and 2p + 1.
      std::vector<Segment> segments;
      /// The segments that hold each system spring's copies.
      std::vector<Holders>             holders;
      std::vector<unsigned int>        first_particle;
      std::vector<double>              inverse_mass;
      std::unique_ptr<tbb::task_arena> arena;
      /// The springs and threads the model was last told of.
      std::size_t  known_springs = 0;
      unsigned int threads       = 1;
    };
  } // namespace

  LACERTA_REGISTER_FORCE_MODEL(
    LinearSprings,
    "linear springs",
    "The paper's springs (Section 3): force k (L - L0) along the "
    "spring, with the optional damping along springs.");
} // namespace lacerta::physics
