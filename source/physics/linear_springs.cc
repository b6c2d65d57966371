// Force model `linear springs`: the paper's springs, f = k (|d| - L0) d/|d|.

#include <lacerta/base/archive.h>
#include <lacerta/base/sort_ids.h>
#include <lacerta/physics/linear_springs.h>
#include <lacerta/physics/particle_system.h>

#include <algorithm>
#include <cmath>

namespace lacerta::physics
{
  namespace
  {
    /// How many springs ahead add_spring_forces() fetches the far ends' data.
    constexpr std::size_t prefetch_distance = 64;

    /// From how many particles a range's positions and forces (48 bytes a particle)
    /// outgrow a second-level cache of 1 MiB, so that fetching ahead pays.
    constexpr std::size_t prefetch_particles = 1u << 15;

    /**
     * Adds the forces of springs [begin, end) to f. Spring s pulls a[s] towards b[s]
     * with k (L - L0) (plus β k (dv·n) along the spring if Damped). If BothEnds is
     * false only the end a[s] is written: the spring crosses into another thread's
     * particles, which computes it too and writes its own end. If Prefetch, the far
     * ends' positions (and forces) are fetched a few springs ahead.
     */
    template <bool Damped, bool BothEnds, bool Prefetch>
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
        // The far ends come from anywhere in the range's particles: fetch those of
        // a later spring ahead (the near ends are in order, the hardware streams
        // them).
        if (Prefetch && s + prefetch_distance < end)
        {
          const unsigned int ahead = 3 * b[s + prefetch_distance];
          __builtin_prefetch(x + ahead);
          if constexpr (BothEnds)
            __builtin_prefetch(f + ahead, 1);
        }
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


    /// The forces of a range's springs: those inside it (both ends) and those that
    /// cross into another range (the range's own end).
    template <bool Damped, bool Prefetch>
    void
    add_all_spring_forces(const SpringSet &inner,
                          const SpringSet &crossing,
                          const double    *x,
                          const double    *v,
                          const double     beta,
                          double          *f)
    {
      add_spring_forces<Damped, true, Prefetch>(inner, 0, inner.size(), x, v, beta, f);
      add_spring_forces<Damped, false, Prefetch>(
        crossing, 0, crossing.size(), x, v, beta, f);
    }


    /// The elastic energy ½ Σ k (L - L0)² of @p set at positions @p x, times @p weight.
    double
    energy_of(const SpringSet &set, const double *x, const double weight)
    {
      double sum = 0;
      for (std::size_t s = 0; s < set.size(); ++s)
      {
        const unsigned int i = 3 * set.a[s], j = 3 * set.b[s];
        const double dx = x[j] - x[i], dy = x[j + 1] - x[i + 1], dz = x[j + 2] - x[i + 2];
        const double stretch =
          std::sqrt(dx * dx + dy * dy + dz * dz) - set.rest_length[s];
        sum += set.stiffness[s] * stretch * stretch;
      }
      return 0.5 * weight * sum;
    }


    /// Whether spring @p s of @p system joins two particles whose motion is
    /// prescribed: its forces act on no free particle.
    bool
    is_held(const ParticleSystem &system, const unsigned int s)
    {
      return system.free[system.springs.a[s]] == 0
             && system.free[system.springs.b[s]] == 0;
    }


    constexpr unsigned int none = static_cast<unsigned int>(-1);

    /// A spring with no copies.
    std::array<unsigned int, 2>
    no_holders()
    {
      return {none, none};
    }
  } // namespace


  void
  LinearSprings::declare_parameters(dealii::ParameterHandler &)
  {
  }


  void
  LinearSprings::set_stiffness_scale(const double scale)
  {
    stiffness_scale = scale;
  }


  double
  LinearSprings::spring_stiffness_scale() const
  {
    return stiffness_scale;
  }


  const ParticleRanges &
  LinearSprings::particle_ranges() const
  {
    return ranges;
  }


  void
  LinearSprings::initialize(const ParticleSystem &system, const unsigned int n_threads)
  {
    // Balance the ranges by the number of spring ends they evaluate.
    std::vector<std::size_t> ends(system.n_particles(), 0);
    for (unsigned int s = 0; s < system.springs.size(); ++s)
      if (!is_held(system, s))
      {
        ++ends[system.springs.a[s]];
        ++ends[system.springs.b[s]];
      }
    ranges.split(system, ends, n_threads);

    segments.assign(2 * ranges.n_parts() + 1, Segment());
    holders.assign(system.springs.size(), no_holders());
    pending_erase.assign(segments.size(), {});
    pending_insert.assign(segments.size(), {});
    for (unsigned int s = 0; s < system.springs.size(); ++s)
      place(system, s);
    apply_pending();
    known_springs = system.springs.size();
  }


  void
  LinearSprings::springs_changed(const ParticleSystem            &system,
                                 const std::vector<unsigned int> &changed)
  {
    const std::size_t n_springs = system.springs.size();
    // New particles join the last range.
    ranges.append_particles(system);

    // The listed springs once each, removed ones first and from the end (their
    // copies are the last of their segments), then the others in order (appended
    // ones go to the ends of their segments). A listed spring may have been
    // appended and removed again since (beyond both counts): it has no copies.
    // A change lists a spring once per cell around it: each is taken once (by a stamp),
    // then the few left are sorted.
    const std::size_t known = std::max(known_springs, n_springs);
    listed_stamp.resize(known, 0);
    if (++listed_mark == 0)
    {
      std::fill(listed_stamp.begin(), listed_stamp.end(), 0);
      listed_mark = 1;
    }
    std::vector<unsigned int> listed;
    const auto                list = [&](const unsigned int s)
    {
      if (s < known && listed_stamp[s] != listed_mark)
      {
        listed_stamp[s] = listed_mark;
        listed.push_back(s);
      }
    };
    for (const unsigned int s : changed)
      list(s);
    for (std::size_t s = n_springs; s < known_springs; ++s)
      list(static_cast<unsigned int>(s));
    std::vector<unsigned int> scratch;
    sort_ids(listed, scratch);
    holders.resize(known, no_holders());
    // place() queues copies per segment; a restored model has none queued yet.
    pending_erase.resize(segments.size());
    pending_insert.resize(segments.size());
    for (auto s = listed.rbegin(); s != listed.rend() && *s >= n_springs; ++s)
      unplace(*s);
    for (const unsigned int s : listed)
      if (s < n_springs)
      {
        place(system, s);
        ranges.update_inverse_mass(system, system.springs.a[s]);
        ranges.update_inverse_mass(system, system.springs.b[s]);
      }
    apply_pending();
    holders.resize(n_springs);
    known_springs = n_springs;

    if (unbalanced())
      LinearSprings::initialize(system, ranges.threads());
  }


  void
  LinearSprings::masses_changed(const ParticleSystem            &system,
                                const std::vector<unsigned int> &particles)
  {
    for (const unsigned int i : particles)
      ranges.update_inverse_mass(system, i);
  }


  void
  LinearSprings::compute_acceleration(const ParticleSystem &system,
                                      const double         *x,
                                      const double         *v,
                                      double               *a,
                                      const RangeUpdate     update) const
  {
    ranges.for_each_part(
      [&](const unsigned int p)
      {
        spring_forces_of_part(system, p, x, v, a);
        ranges.finish_accelerations(system, p, v, a);
        update(ranges.begin(p), ranges.end(p));
      });
  }


  void
  LinearSprings::compute_spring_forces(const ParticleSystem &system,
                                       const double         *x,
                                       const double         *v,
                                       double               *f) const
  {
    ranges.for_each_part([&](const unsigned int p)
                         { spring_forces_of_part(system, p, x, v, f); });
  }


  unsigned int
  LinearSprings::held_segment() const
  {
    return static_cast<unsigned int>(segments.size() - 1);
  }


  double
  LinearSprings::elastic_energy(const ParticleSystem &, const double *x) const
  {
    // Over the thread ranges, like the forces: a spring inside a range once, one
    // between two ranges as a copy in each, counted half. The parts' sums are added in
    // order, so the result depends on the partition but not on the threads' timing.
    part_energy.assign(ranges.n_parts(), 0.0);
    ranges.for_each_part(
      [&](const unsigned int p)
      {
        part_energy[p] = energy_of(segments[2 * p].set, x, 1.0)
                         + energy_of(segments[2 * p + 1].set, x, 0.5);
      });
    double energy = 0;
    for (const double e : part_energy)
      energy += e;
    return energy;
  }


  std::size_t
  LinearSprings::slot(const unsigned int g, const unsigned int s) const
  {
    const std::vector<unsigned int> &origin = segments[g].origin;
    return std::lower_bound(origin.begin(), origin.end(), s) - origin.begin();
  }


  void
  LinearSprings::erase(const unsigned int g, const unsigned int s)
  {
    Segment          &segment = segments[g];
    const std::size_t k       = slot(g, s);
    segment.set.a.erase(segment.set.a.begin() + k);
    segment.set.b.erase(segment.set.b.begin() + k);
    segment.set.stiffness.erase(segment.set.stiffness.begin() + k);
    segment.set.rest_length.erase(segment.set.rest_length.begin() + k);
    segment.origin.erase(segment.origin.begin() + k);
  }


  void
  LinearSprings::unplace(const unsigned int s)
  {
    for (const unsigned int g : holders[s])
      if (g != none)
        erase(g, s);
    holders[s] = no_holders();
  }


  void
  LinearSprings::place(const ParticleSystem &system, const unsigned int s)
  {
    const SpringSet   &all = system.springs;
    const unsigned int a = all.a[s], b = all.b[s];
    const unsigned int pa = ranges.part_of(a), pb = ranges.part_of(b);
    const double       k = stiffness_scale * all.stiffness[s];
    // (segment, first end, second end) of each copy.
    std::array<std::array<unsigned int, 3>, 2> wanted = {{{2 * pa, a, b}, {none, 0, 0}}};
    if (is_held(system, s))
      wanted[0][0] = held_segment();
    else if (pa != pb)
      wanted = {{{2 * pa + 1, a, b}, {2 * pb + 1, b, a}}};
    for (const unsigned int g : holders[s])
      if (g != none && g != wanted[0][0] && g != wanted[1][0])
        pending_erase[g].push_back(s);
    const Holders old = holders[s];
    holders[s]        = no_holders();
    for (unsigned int c = 0; c < 2; ++c)
    {
      const auto [g, from, to] = wanted[c];
      if (g == none)
        continue;
      holders[s][c] = g;
      if (g == old[0] || g == old[1])
      {
        Segment          &segment       = segments[g];
        const std::size_t slot_k        = slot(g, s);
        segment.set.a[slot_k]           = from;
        segment.set.b[slot_k]           = to;
        segment.set.stiffness[slot_k]   = k;
        segment.set.rest_length[slot_k] = all.rest_length[s];
        continue;
      }
      pending_insert[g].push_back({s, from, to, k, all.rest_length[s]});
    }
  }


  void
  LinearSprings::apply_pending()
  {
    for (std::size_t g = 0; g < pending_erase.size(); ++g)
    {
      Segment &segment = segments[g];
      auto    &gone    = pending_erase[g];
      if (!gone.empty())
      {
        std::sort(gone.begin(), gone.end());
        std::size_t out = 0, next = 0;
        for (std::size_t i = 0; i < segment.origin.size(); ++i)
        {
          while (next < gone.size() && gone[next] < segment.origin[i])
            ++next;
          if (next < gone.size() && gone[next] == segment.origin[i])
            continue;
          segment.origin[out]          = segment.origin[i];
          segment.set.a[out]           = segment.set.a[i];
          segment.set.b[out]           = segment.set.b[i];
          segment.set.stiffness[out]   = segment.set.stiffness[i];
          segment.set.rest_length[out] = segment.set.rest_length[i];
          ++out;
        }
        segment.origin.resize(out);
        segment.set.a.resize(out);
        segment.set.b.resize(out);
        segment.set.stiffness.resize(out);
        segment.set.rest_length.resize(out);
        gone.clear();
      }
      auto &come = pending_insert[g];
      if (come.empty())
        continue;
      std::sort(come.begin(),
                come.end(),
                [](const PendingCopy &x, const PendingCopy &y) { return x.s < y.s; });
      // Merged from the back, in place: the segment grows by the copies that come.
      const std::size_t n = segment.origin.size(), m = come.size();
      segment.origin.resize(n + m);
      segment.set.a.resize(n + m);
      segment.set.b.resize(n + m);
      segment.set.stiffness.resize(n + m);
      segment.set.rest_length.resize(n + m);
      std::size_t i = n, j = m, out = n + m;
      while (j > 0)
      {
        --out;
        if (i > 0 && segment.origin[i - 1] > come[j - 1].s)
        {
          --i;
          segment.origin[out]          = segment.origin[i];
          segment.set.a[out]           = segment.set.a[i];
          segment.set.b[out]           = segment.set.b[i];
          segment.set.stiffness[out]   = segment.set.stiffness[i];
          segment.set.rest_length[out] = segment.set.rest_length[i];
        }
        else
        {
          --j;
          segment.origin[out]          = come[j].s;
          segment.set.a[out]           = come[j].from;
          segment.set.b[out]           = come[j].to;
          segment.set.stiffness[out]   = come[j].stiffness;
          segment.set.rest_length[out] = come[j].rest_length;
        }
      }
      come.clear();
    }
  }


  bool
  LinearSprings::unbalanced() const
  {
    std::vector<std::size_t> loads(ranges.n_parts());
    for (std::size_t p = 0; p < loads.size(); ++p)
      loads[p] = segments[2 * p].origin.size() + segments[2 * p + 1].origin.size();
    return ParticleRanges::unbalanced(loads);
  }


  void
  LinearSprings::spring_forces_of_part(const ParticleSystem &system,
                                       const unsigned int    p,
                                       const double         *x,
                                       const double         *v,
                                       double               *f) const
  {
    ranges.zero(p, f);
    const double     beta     = system.spring_damping;
    const SpringSet &inner    = segments[2 * p].set;
    const SpringSet &crossing = segments[2 * p + 1].set;
    const bool       prefetch = ranges.end(p) - ranges.begin(p) >= prefetch_particles;
    if (beta > 0 && prefetch)
      add_all_spring_forces<true, true>(inner, crossing, x, v, beta, f);
    else if (beta > 0)
      add_all_spring_forces<true, false>(inner, crossing, x, v, beta, f);
    else if (prefetch)
      add_all_spring_forces<false, true>(inner, crossing, x, v, beta, f);
    else
      add_all_spring_forces<false, false>(inner, crossing, x, v, beta, f);
  }


  LACERTA_REGISTER_FORCE_MODEL(
    LinearSprings,
    "linear springs",
    "The paper's springs (Section 3): force k (L - L0) along the "
    "spring, with the optional damping along springs.");


  void
  LinearSprings::serialize(Archive &archive)
  {
    archive(ranges, holders, known_springs, stiffness_scale);
    std::size_t n = segments.size();
    archive    &n;
    segments.resize(archive.size(n, 1));
    for (Segment &segment : segments)
      archive(segment.set, segment.origin);
  }
} // namespace lacerta::physics
