/**
 * @file
 * Work over a whole particle system spread over its force model's thread ranges.
 */
#pragma once

#include <lacerta/physics/force_model.h>
#include <lacerta/physics/particle_ranges.h>
#include <lacerta/physics/particle_system.h>

#include <cstddef>

namespace lacerta::physics
{
  /**
   * The force model's thread ranges if there are several and they cover the system's
   * particles, so that work spread over them runs on the model's threads (as many as
   * the run asked for); nullptr otherwise (no model yet, or one thread): the work then
   * runs as one part.
   */
  inline const ParticleRanges *
  thread_ranges(const ParticleSystem &system)
  {
    if (!system.has_force_model())
      return nullptr;
    const ParticleRanges &ranges = system.force_model().particle_ranges();
    const unsigned int    parts  = ranges.n_parts();
    if (parts < 2 || ranges.begin(0) != 0
        || ranges.end(parts - 1) != system.n_particles())
      return nullptr;
    return &ranges;
  }


  /**
   * Runs @p work(begin, end) over contiguous ranges of the system's particles that
   * together cover them once, in parallel on the force model's threads. Work that
   * writes only the entries of its range's particles needs no atomics, and a pass
   * over the springs that adds to a row only in the range of its particle adds every
   * row's terms in spring order, as one pass over all rows would: the same sums to the
   * bit on any number of threads.
   */
  template <typename Work>
  void
  for_each_particle_range(const ParticleSystem &system, const Work &work)
  {
    if (const ParticleRanges *ranges = thread_ranges(system))
      ranges->for_each_part([&](const unsigned int p)
                            { work(ranges->begin(p), ranges->end(p)); });
    else
      work(0u, system.n_particles());
  }


  /**
   * Runs @p work(begin, end) over the coordinates (3 per particle) of the ranges of
   * for_each_particle_range(): for an integrator's updates of positions and
   * velocities, elementwise, so the same to the bit on any number of threads.
   */
  template <typename Work>
  void
  for_each_coordinate_range(const ParticleSystem &system, const Work &work)
  {
    for_each_particle_range(system,
                            [&](const unsigned int begin, const unsigned int end)
                            { work(std::size_t(3) * begin, std::size_t(3) * end); });
  }


  /**
   * Runs @p work(begin, end) over contiguous ranges of the system's springs that
   * together cover them once, in parallel on the force model's threads (for work that
   * writes only the springs' own entries).
   */
  template <typename Work>
  void
  for_each_spring_range(const ParticleSystem &system, const Work &work)
  {
    const std::size_t n = system.springs.size();
    if (const ParticleRanges *ranges = thread_ranges(system))
    {
      const std::size_t parts = ranges->n_parts();
      ranges->for_each_part([&](const unsigned int p)
                            { work(n * p / parts, n * (p + 1) / parts); });
    }
    else
      work(std::size_t(0), n);
  }
} // namespace lacerta::physics
