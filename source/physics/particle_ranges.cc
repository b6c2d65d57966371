#include <lacerta/base/archive.h>
#include <lacerta/physics/particle_ranges.h>
#include <lacerta/physics/particle_system.h>

#include <algorithm>
#include <cstring>

namespace lacerta::physics
{
  void
  ParticleRanges::split(const ParticleSystem           &system,
                        const std::vector<std::size_t> &load,
                        const unsigned int              threads)
  {
    n_threads                  = threads;
    const unsigned int n       = system.n_particles();
    const unsigned int n_parts = std::max(1u, std::min(threads, std::max(1u, n / 64)));
    std::vector<std::size_t> cumulative(n + 1, 0);
    for (unsigned int i = 0; i < n; ++i)
      cumulative[i + 1] = cumulative[i] + load[i];
    first_particle.assign(n_parts + 1, n);
    first_particle[0] = 0;
    for (unsigned int p = 1; p < n_parts; ++p)
      first_particle[p] = std::lower_bound(cumulative.begin(),
                                           cumulative.end(),
                                           cumulative[n] * p / n_parts)
                          - cumulative.begin();
    inverse_mass.resize(n);
    for (unsigned int i = 0; i < n; ++i)
      update_inverse_mass(system, i);
    arena = std::make_unique<tbb::task_arena>(static_cast<int>(n_parts));
  }


  bool
  ParticleRanges::unbalanced(const std::vector<std::size_t> &loads)
  {
    if (loads.size() <= 1)
      return false;
    std::size_t total = 0, largest = 0;
    for (const std::size_t load : loads)
    {
      total += load;
      largest = std::max(largest, load);
    }
    return largest > 1.1 * total / loads.size() + 256;
  }


  unsigned int
  ParticleRanges::part_of(const unsigned int i) const
  {
    return static_cast<unsigned int>(
      std::upper_bound(first_particle.begin() + 1, first_particle.end() - 1, i)
      - first_particle.begin() - 1);
  }


  void
  ParticleRanges::append_particles(const ParticleSystem &system)
  {
    // Particles removed from the end (a coarser level of detail) shorten the last
    // ranges, which may become empty.
    const unsigned int n = system.n_particles();
    for (unsigned int &first : first_particle)
      first = std::min(first, n);
    first_particle.back() = n;
    const std::size_t old = inverse_mass.size();
    inverse_mass.resize(n);
    for (std::size_t i = old; i < n; ++i)
      update_inverse_mass(system, i);
  }


  void
  ParticleRanges::update_inverse_mass(const ParticleSystem &system, const std::size_t i)
  {
    inverse_mass[i] = system.mass[i] > 0 ? 1.0 / system.mass[i] : 0.0;
  }


  void
  ParticleRanges::zero(const unsigned int p, double *f) const
  {
    std::memset(f + 3 * std::size_t(first_particle[p]),
                0,
                3 * sizeof(double) * (first_particle[p + 1] - first_particle[p]));
  }


  void
  ParticleRanges::finish_accelerations(const ParticleSystem &system,
                                       const unsigned int    p,
                                       const double         *v,
                                       double               *a) const
  {
    const double *g   = system.body_acceleration.data();
    const double  c   = system.mass_damping;
    const double *ext = system.external_force.data();
    for (unsigned int i = first_particle[p]; i < first_particle[p + 1]; ++i)
    {
      const double m_inv = inverse_mass[i];
      const double keep  = system.free[i];
      for (unsigned int d = 0; d < 3; ++d)
        a[3 * i + d] =
          keep * ((a[3 * i + d] + ext[3 * i + d]) * m_inv + g[d] - c * v[3 * i + d]);
    }
  }


  void
  ParticleRanges::serialize(Archive &archive)
  {
    archive(first_particle, inverse_mass, n_threads);
  }
} // namespace lacerta::physics
