/**
 * @file
 * The particles of a force model split into one contiguous range per thread.
 */
#pragma once

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/partitioner.h>
#include <tbb/task_arena.h>

#include <cstddef>
#include <memory>
#include <vector>

namespace lacerta
{
  class Archive;
}
namespace lacerta::physics
{
  class ParticleSystem;

  /**
   * The particles split into contiguous ranges, one per thread, each owning the forces
   * and accelerations of its particles: a force model evaluates in range p only what
   * acts on p's particles and writes only their entries, so no thread writes another's
   * memory (no atomics, no locks, no reduction). Keeps the inverse masses and finishes
   * the accelerations of a range (loads, body acceleration, damping, constraints).
   */
  class ParticleRanges
  {
  public:
    /**
     * Splits the system's particles into at most @p n_threads ranges (one per 64
     * particles at the least) of about equal load, @p load[i] the load of particle i,
     * and reads the inverse masses.
     */
    void
    split(const ParticleSystem           &system,
          const std::vector<std::size_t> &load,
          unsigned int                    n_threads);

    /// The number of ranges.
    unsigned int
    n_parts() const
    {
      return static_cast<unsigned int>(first_particle.size() - 1);
    }

    /// The first particle of range @p p.
    unsigned int
    begin(const unsigned int p) const
    {
      return first_particle[p];
    }

    /// One past the last particle of range @p p.
    unsigned int
    end(const unsigned int p) const
    {
      return first_particle[p + 1];
    }

    /// The range of particle @p i.
    unsigned int
    part_of(unsigned int i) const;

    /// The thread count the ranges were last split for.
    unsigned int
    threads() const
    {
      return n_threads;
    }

    /**
     * The system gained particles (a cut): they join the last range, and their inverse
     * masses are read. Or it lost its last particles (a coarser level of detail): the
     * ranges past the new end shrink, possibly to nothing.
     */
    void
    append_particles(const ParticleSystem &system);

    /// Reads the inverse mass of particle @p i again (0 for a massless particle).
    void
    update_inverse_mass(const ParticleSystem &system, std::size_t i);

    /// Zeroes the forces @p f (3 per particle) of range @p p's particles.
    void
    zero(unsigned int p, double *f) const;

    /**
     * Turns the forces @p a of range @p p's particles (elastic forces, in place) into
     * accelerations: adds the external forces, divides by the masses, adds the body
     * acceleration and the mass damping -c v, and zeroes constrained particles.
     */
    void
    finish_accelerations(const ParticleSystem &system,
                         unsigned int          p,
                         const double         *v,
                         double               *a) const;

    /**
     * Whether the ranges' loads @p loads (the work of each range, in any unit) are
     * so uneven that the ranges should be split again: the largest exceeds the mean
     * by more than a tenth (and by 256, so that a small system is not split again for
     * a few springs). A step waits for the largest range, while a new split costs
     * about one evaluation, amortised over the growth that unbalanced the ranges
     * (appended particles join the last range).
     */
    static bool
    unbalanced(const std::vector<std::size_t> &loads);

    /// Runs @p work(p) for every range, in parallel if there is more than one.
    template <typename Work>
    void
    for_each_part(const Work &work) const
    {
      const unsigned int parts = n_parts();
      if (parts == 1)
      {
        work(0);
        return;
      }
      arena->execute(
        [&]
        {
          tbb::parallel_for(
            tbb::blocked_range<unsigned int>(0, parts, 1),
            [&](const tbb::blocked_range<unsigned int> &range)
            {
              for (unsigned int p = range.begin(); p < range.end(); ++p)
                work(p);
            },
            tbb::static_partitioner());
        });
    }

    /// Writes or reads the ranges for a checkpoint (see lacerta::Archive).
    void
    serialize(Archive &archive);

  private:
    /// Range p is [first_particle[p], first_particle[p + 1]).
    std::vector<unsigned int>        first_particle = {0, 0};
    std::vector<double>              inverse_mass;
    std::unique_ptr<tbb::task_arena> arena;
    unsigned int                     n_threads = 1;
  };
} // namespace lacerta::physics
