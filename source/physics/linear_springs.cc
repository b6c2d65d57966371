// Force model `linear springs`: the paper's springs, f = k (|d| - L0) d/|d|.

#include <lacerta/physics/force_model.h>
#include <lacerta/physics/particle_system.h>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/partitioner.h>
#include <tbb/task_arena.h>

#include <algorithm>
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
        std::vector<unsigned int> part_of(n);
        for (unsigned int p = 0; p < n_parts; ++p)
          for (unsigned int i = first_particle[p]; i < first_particle[p + 1]; ++i)
            part_of[i] = p;

        std::vector<SpringSet> inner(n_parts), crossing(n_parts);
        const SpringSet       &all = system.springs;
        for (std::size_t s = 0; s < all.size(); ++s)
        {
          const unsigned int pa = part_of[all.a[s]], pb = part_of[all.b[s]];
          if (pa == pb)
            inner[pa].push_back(all.a[s], all.b[s], all.stiffness[s], all.rest_length[s]);
          else
          {
            crossing[pa].push_back(all.a[s],
                                   all.b[s],
                                   all.stiffness[s],
                                   all.rest_length[s]);
            crossing[pb].push_back(all.b[s],
                                   all.a[s],
                                   all.stiffness[s],
                                   all.rest_length[s]);
          }
        }
        springs.clear();
        offsets.assign(n_parts, {});
        for (unsigned int p = 0; p < n_parts; ++p)
        {
          offsets[p][0] = springs.size();
          append(springs, inner[p]);
          offsets[p][1] = springs.size();
          append(springs, crossing[p]);
          offsets[p][2] = springs.size();
        }

        inverse_mass.resize(n);
        for (unsigned int i = 0; i < n; ++i)
          inverse_mass[i] = system.mass[i] > 0 ? 1.0 / system.mass[i] : 0.0;
        arena = std::make_unique<tbb::task_arena>(static_cast<int>(n_parts));
      }

      void
      masses_changed(const ParticleSystem            &system,
                     const std::vector<unsigned int> &particles) override
      {
        for (const unsigned int i : particles)
          inverse_mass[i] = system.mass[i] > 0 ? 1.0 / system.mass[i] : 0.0;
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
      static void
      append(SpringSet &to, const SpringSet &from)
      {
        to.a.insert(to.a.end(), from.a.begin(), from.a.end());
        to.b.insert(to.b.end(), from.b.begin(), from.b.end());
        to.stiffness.insert(to.stiffness.end(),
                            from.stiffness.begin(),
                            from.stiffness.end());
        to.rest_length.insert(to.rest_length.end(),
                              from.rest_length.begin(),
                              from.rest_length.end());
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
        const double beta = system.spring_damping;
        if (beta > 0)
        {
          add_spring_forces<true, true>(
            springs, offsets[p][0], offsets[p][1], x, v, beta, f);
          add_spring_forces<true, false>(
            springs, offsets[p][1], offsets[p][2], x, v, beta, f);
        }
        else
        {
          add_spring_forces<false, true>(
            springs, offsets[p][0], offsets[p][1], x, v, beta, f);
          add_spring_forces<false, false>(
            springs, offsets[p][1], offsets[p][2], x, v, beta, f);
        }
      }

      /// Runs @p work(p) for every part, in parallel if there is more than one.
      template <typename Work>
      void
      for_each_part(const Work &work) const
      {
        const unsigned int n_parts = offsets.size();
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

      SpringSet                               springs;
      std::vector<std::array<std::size_t, 3>> offsets;
      std::vector<unsigned int>               first_particle;
      std::vector<double>                     inverse_mass;
      std::unique_ptr<tbb::task_arena>        arena;
    };
  } // namespace

  LACERTA_REGISTER_FORCE_MODEL(
    LinearSprings,
    "linear springs",
    "The paper's springs (Section 3): force k (L - L0) along the "
    "spring, with the optional damping along springs.");
} // namespace lacerta::physics
