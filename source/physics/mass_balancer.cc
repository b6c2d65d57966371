#include <lacerta/base/archive.h>
#include <lacerta/base/exceptions.h>
#include <lacerta/mesh/tet_mesh.h>
#include <lacerta/physics/mass_balancer.h>
#include <lacerta/physics/particle_system.h>
#include <lacerta/physics/stability.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <vector>

namespace lacerta::physics
{
  namespace
  {
    /**
     * Moves @p amount of mass from particle @p from to particle @p to, with the
     * velocity of @p from: momentum is kept, and kinetic energy cannot grow (a particle
     * made heavier at its own velocity would gain energy from nothing).
     */
    void
    move_mass(ParticleSystem    &system,
              const unsigned int from,
              const unsigned int to,
              const double       amount)
    {
      const double m = system.mass[to] + amount;
      for (unsigned int c = 0; c < 3; ++c)
        system.velocity[3 * to + c] = m > 0
                                        ? (system.mass[to] * system.velocity[3 * to + c]
                                           + amount * system.velocity[3 * from + c])
                                            / m
                                        : system.velocity[3 * from + c];
      system.mass[from] -= amount;
      system.mass[to] = m;
    }


    /**
     * Raises particle @p i's mass by @p need, taking it from the free particles within
     * @p reach springs, ring by ring: a ring that has enough gives in proportion to
     * what each of its particles can spare (half of what it has above the mass that
     * keeps its own bound at @p limit); otherwise it gives all it can and the next ring
     * is asked. All or nothing: when the particles within reach cannot spare @p need
     * together, nothing moves (mass that leaves the particle above the target does not
     * lower the largest bound, and only changes the dynamics). Calls
     * @p on_gift(donor, mass) for every gift, before the mass moves; returns the mass
     * moved.
     */
    template <typename ForEachNeighbour, typename RowSum, typename OnGift>
    double
    borrow(ParticleSystem            &system,
           const ForEachNeighbour    &for_each_neighbour,
           const RowSum              &row_sum,
           const unsigned int         i,
           const double               need,
           const double               limit,
           const unsigned int         reach,
           std::vector<char>         &seen,
           std::vector<double>       &spare,
           std::vector<unsigned int> &donors,
           std::vector<unsigned int> &first,
           std::vector<unsigned int> &ring,
           const OnGift              &on_gift)
    {
      // The donors, ring by ring (ring r starts at first[r]), and what each can spare
      // (the vectors are the caller's, kept between calls).
      donors.clear();
      first.assign(1, 0);
      ring.assign(1, i);
      seen[i]          = 1;
      double available = 0;
      for (unsigned int hop = 0; hop < reach && available < need && !ring.empty(); ++hop)
      {
        for (const unsigned int p : ring)
          for_each_neighbour(p,
                             [&](const unsigned int j)
                             {
                               if (seen[j] || !(system.free[j] > 0))
                                 return;
                               seen[j] = 1;
                               if (spare.size() <= donors.size())
                                 spare.resize(2 * donors.size() + 16);
                               spare[donors.size()] =
                                 std::max(0.0,
                                          0.5 * (system.mass[j] - row_sum(j) / limit));
                               available += spare[donors.size()];
                               donors.push_back(j);
                             });
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
          if (given > 0)
            on_gift(donors[d], given);
          move_mass(system, donors[d], i, given);
        }
        left -= fraction * in_ring;
      }
      return need - std::max(0.0, left);
    }
  } // namespace


  void
  MassBalancer::require_mesh(const ParticleSystem &system)
  {
    if (system.mesh == nullptr || !system.mesh->has_local_updates())
      throw_error("MassBalancer: internal error, the particle system needs its mesh, "
                  "with local updates (TetMesh::enable_local_updates()): the springs "
                  "around a particle are found through its cells.");
  }


  void
  MassBalancer::record_gift(const unsigned int donor,
                            const unsigned int taker,
                            const double       mass)
  {
    const auto id = static_cast<unsigned int>(gifts.size());
    gifts.push_back({donor, taker, mass});
    gifts_of[donor].push_back(id);
    gifts_of[taker].push_back(id);
    ++n_live_gifts;
  }


  void
  MassBalancer::compact_gifts()
  {
    // Gifts taken back stay in the ledger until they are most of it: then it is
    // rebuilt from the live ones (amortised over the gifts taken back).
    if (gifts.size() < 1024 || gifts.size() < 2 * std::size_t(n_live_gifts))
      return;
    std::vector<Gift> live;
    live.reserve(n_live_gifts);
    for (const Gift &g : gifts)
      if (g.mass > 0)
        live.push_back(g);
    gifts.clear();
    n_live_gifts = 0;
    for (auto &list : gifts_of)
      list.clear();
    for (const Gift &g : live)
      record_gift(g.donor, g.taker, g.mass);
  }


  MassBalancer::MassBalancer(const ParticleSystem &system, const unsigned int reach)
      : target_lambda(0)
      , reach(std::max(1u, reach))
  {
    require_mesh(system);
    // The row sums at rest of every particle, the bound at each over its mass.
    std::vector<unsigned int> all(system.n_particles());
    for (unsigned int i = 0; i < system.n_particles(); ++i)
      all[i] = i;
    std::vector<double> row(all.size());
    gershgorin_row_sums(system, system.rest_position().data(), all, scratch, row.data());
    for (unsigned int i = 0; i < system.n_particles(); ++i)
      if (system.free[i] > 0)
        target_lambda =
          std::max(target_lambda,
                   system.mass[i] > 0 ? row[i] / system.mass[i]
                                      : std::numeric_limits<double>::infinity());
  }


  MassBalanceStatistics
  MassBalancer::balance(ParticleSystem &system)
  {
    // From the lumped masses: the result depends on the mesh, not on the changes that
    // led to it. Then every particle is a changed one.
    const unsigned int        n      = system.n_particles();
    const std::vector<double> before = system.mass;
    system.mass_shift.resize(n, 0.0);
    for (unsigned int i = 0; i < n; ++i)
    {
      system.mass[i] -= system.mass_shift[i];
      system.mass_shift[i] = 0;
    }
    gifts.clear();
    gifts_of.assign(n, {});
    n_live_gifts   = 0;
    positive_shift = 0;
    n_unresolved   = 0;
    unresolved.assign(n, 0);
    std::vector<unsigned int> all(n);
    for (unsigned int i = 0; i < n; ++i)
      all[i] = i;
    const MassBalanceStatistics statistics = rebalance(system, all);
    std::vector<unsigned int>   changed;
    for (unsigned int i = 0; i < n; ++i)
      if (system.mass[i] != before[i])
        changed.push_back(i);
    if (!changed.empty())
      system.masses_changed(changed);
    return statistics;
  }


  MassBalanceStatistics
  MassBalancer::rebalance(ParticleSystem                  &system,
                          const std::vector<unsigned int> &particles)
  {
    MassBalanceStatistics statistics;
    const unsigned int    n = system.n_particles();
    system.mass_shift.resize(n, 0.0);
    unresolved.resize(n, 0);
    if (!(target_lambda > 0) || !std::isfinite(target_lambda) || particles.empty())
    {
      statistics.moved      = positive_shift;
      statistics.unresolved = n_unresolved;
      return statistics;
    }
    require_mesh(system);
    start_rebalance(system, particles);
    const double limit = donor_headroom * target_lambda;
    take_back_gifts(system, limit);
    return_gifts(system);
    statistics.raised = raise_particles(system, limit);
    record_changes(system, limit);
    statistics.moved      = positive_shift;
    statistics.unresolved = n_unresolved;
    return statistics;
  }


  template <typename F>
  void
  MassBalancer::for_each_neighbour(const mesh::TetMesh &mesh,
                                   const unsigned int   p,
                                   const F             &f)
  {
    // The particles joined to p by a spring: the other vertices of its cells.
    if (++stamp == 0)
    {
      std::fill(mark.begin(), mark.end(), 0);
      stamp = 1;
    }
    mark[p] = stamp;
    for (const unsigned int t : mesh.tets_of_vertex(p))
      for (const unsigned int q : mesh.tet(t))
        if (mark[q] != stamp)
        {
          mark[q] = stamp;
          f(q);
        }
  }


  void
  MassBalancer::touch(const ParticleSystem &system, const unsigned int p)
  {
    if (touched_mark[p] != touched_stamp)
    {
      touched_mark[p] = touched_stamp;
      touched.push_back(p);
      before_of[p] = system.mass[p];
    }
  }


  void
  MassBalancer::compute_rows(const ParticleSystem            &system,
                             const std::vector<unsigned int> &rows)
  {
    row_values.resize(rows.size());
    gershgorin_row_sums(
      system, system.rest_position().data(), rows, scratch, row_values.data());
    for (std::size_t k = 0; k < rows.size(); ++k)
    {
      row_sum[rows[k]]   = row_values[k];
      row_known[rows[k]] = row_stamp;
    }
  }


  double
  MassBalancer::row(const ParticleSystem &system, const unsigned int j)
  {
    if (row_known[j] != row_stamp)
    {
      single_row.assign(1, j);
      compute_rows(system, single_row);
    }
    return row_sum[j];
  }


  void
  MassBalancer::start_rebalance(const ParticleSystem            &system,
                                const std::vector<unsigned int> &particles)
  {
    const unsigned int n = system.n_particles();
    mark.resize(n, 0);
    in_region.resize(n, 0);
    gifts_of.resize(n);
    before_of.resize(n, 0.0);
    momentum_of.resize(3 * std::size_t(n), 0.0);
    mass_in.resize(n, 0.0);
    mass_out.resize(n, 0.0);
    outgoing.resize(3 * std::size_t(n), 0.0);
    touched.clear();
    // Gifts between particles within reach of the change are taken back: the change
    // may have separated giver and taker (a cut between them crosses an edge of every
    // path of at most `reach` springs, at changed particles), and the changed
    // particles' needs are decided again. Their takers are checked again too.
    to_check.assign(particles.begin(), particles.end());
    std::sort(to_check.begin(), to_check.end());
    to_check.erase(std::unique(to_check.begin(), to_check.end()), to_check.end());
    touched_mark.resize(n, 0);
    if (++touched_stamp == 0)
    {
      std::fill(touched_mark.begin(), touched_mark.end(), 0);
      touched_stamp = 1;
    }
    // The region: the particles within reach of those to check (distinct), after
    // them; in_region marks them all.
    region.clear();
    for (const unsigned int p : to_check)
      if (!in_region[p])
      {
        in_region[p] = 1;
        region.push_back(p);
      }
    for (std::size_t first = 0, hop = 0; hop < reach; ++hop)
    {
      const std::size_t last = region.size();
      for (std::size_t k = first; k < last; ++k)
        for_each_neighbour(*system.mesh,
                           region[k],
                           [&](const unsigned int q)
                           {
                             if (!in_region[q])
                             {
                               in_region[q] = 1;
                               region.push_back(q);
                             }
                           });
      first = last;
    }
    // The rows at rest, computed when first asked for (row()): those of the particles
    // to check at once, a donor's when its taker asks its ring. A particle the change
    // did not touch and that gives nothing keeps its mass and its springs, hence its
    // row and whether it is above the limit: the cost follows the particles that need
    // mass, not every particle within reach of the change.
    if (++row_stamp == 0)
    {
      std::fill(row_known.begin(), row_known.end(), 0);
      row_stamp = 1;
    }
    row_known.resize(n, 0);
    row_sum.resize(n, 0.0);
    compute_rows(system, to_check);
  }


  void
  MassBalancer::take_back_gifts(const ParticleSystem &system, const double limit)
  {
    // A taker left unable to afford what it gave on (its mass after the take-backs
    // below what keeps its bound at the donors' limit, or even negative) owes it: its
    // own gifts are taken back with it (cascade). One that can afford them keeps
    // them: otherwise the light particles along a crack, each raised in part by the
    // one before, would form chains of gifts as long as the crack, and every cut step
    // would take back and give again along all of it. The gifts are taken back at
    // once, each with the velocity its taker has now (return_gifts()): taken back one
    // after the other, a particle could hold a negative mass in between, and the
    // velocity of what it then receives would be divided by it.
    cascade.clear();
    taken_back.clear();
    pending.resize(system.n_particles(), 0.0);
    const auto take_back = [&](const unsigned int g)
    {
      Gift &gift = gifts[g];
      touch(system, gift.donor);
      touch(system, gift.taker);
      taken_back.push_back(g);
      to_check.push_back(gift.taker);
      cascade.push_back(gift.taker);
      returned[g] = gift.mass;
      pending[gift.taker] -= gift.mass;
      pending[gift.donor] += gift.mass;
      gift.mass = 0;
      --n_live_gifts;
    };
    returned.resize(gifts.size(), 0.0);
    for (const unsigned int p : region)
      for (const unsigned int g : gifts_of[p])
        if (gifts[g].mass > 0)
          take_back(g);
    while (!cascade.empty())
    {
      const unsigned int t = cascade.back();
      cascade.pop_back();
      if (system.mass[t] + pending[t] >= row(system, t) / limit)
        continue;
      for (const unsigned int g : gifts_of[t])
        if (gifts[g].mass > 0 && gifts[g].donor == t)
          take_back(g);
    }
    for (const unsigned int p : touched)
      pending[p] = 0;
  }


  void
  MassBalancer::return_gifts(ParticleSystem &system)
  {
    // Mass and momentum: each gift goes back to its donor with the velocity u of its
    // taker, and every particle's new velocity is the mass-weighted mean of what it
    // keeps and what it receives, so momentum is kept and kinetic energy cannot grow
    // (every step is a merge of parcels of mass). A particle keeps what it had less
    // what leaves it at its velocity, u = v. One that returns more than it has (a cut
    // took the cells of a donor that was also a taker) first receives, then returns
    // at the velocity it then has, u = (m v + Σ m_g u_g) / (m + Σ m_g) over the gifts
    // coming back to it; those velocities can depend on each other along chains of
    // gifts, so they are solved by Gauss-Seidel sweeps. Returning at the velocity before
    // receiving would divide the momentum of what comes back by the small mass left, and
    // create kinetic energy. A mass made negative by a cut counts as 0 in the means.
    for (const unsigned int p : touched)
    {
      mass_in[p]  = 0;
      mass_out[p] = 0;
      for (unsigned int c = 0; c < 3; ++c)
        outgoing[3 * p + c] = system.velocity[3 * p + c];
    }
    for (const unsigned int g : taken_back)
    {
      mass_out[gifts[g].taker] += returned[g];
      mass_in[gifts[g].donor] += returned[g];
    }
    const auto returns_more_than_it_has = [&](const unsigned int p)
    { return system.mass[p] < mass_out[p] && mass_in[p] > 0; };
    // Their velocities by Gauss-Seidel sweeps over the gifts coming back to them
    // (diagonally dominant: each one's mass and what it receives).
    deficit_gifts.clear();
    for (const unsigned int g : taken_back)
      if (returns_more_than_it_has(gifts[g].donor))
        deficit_gifts.push_back(g);
    std::sort(deficit_gifts.begin(),
              deficit_gifts.end(),
              [&](const unsigned int a, const unsigned int b)
              { return gifts[a].donor < gifts[b].donor; });
    for (unsigned int sweep = 0; sweep < max_velocity_sweeps && !deficit_gifts.empty();
         ++sweep)
    {
      double change = 0, scale = 0;
      for (std::size_t k = 0; k < deficit_gifts.size();)
      {
        const unsigned int    p   = gifts[deficit_gifts[k]].donor;
        const double          own = std::max(system.mass[p], 0.0);
        std::array<double, 3> u{};
        for (unsigned int c = 0; c < 3; ++c)
          u[c] = own * system.velocity[3 * p + c];
        for (; k < deficit_gifts.size() && gifts[deficit_gifts[k]].donor == p; ++k)
        {
          const unsigned int g = deficit_gifts[k];
          for (unsigned int c = 0; c < 3; ++c)
            u[c] += returned[g] * outgoing[3 * gifts[g].taker + c];
        }
        for (unsigned int c = 0; c < 3; ++c)
        {
          u[c] /= own + mass_in[p];
          change              = std::max(change, std::abs(u[c] - outgoing[3 * p + c]));
          scale               = std::max(scale, std::abs(u[c]));
          outgoing[3 * p + c] = u[c];
        }
      }
      if (change <= 1e-15 * scale)
        break;
    }
    // What each particle receives, at the velocities the gifts return with.
    for (const unsigned int p : touched)
      for (unsigned int c = 0; c < 3; ++c)
        momentum_of[3 * p + c] = 0;
    for (const unsigned int g : taken_back)
      for (unsigned int c = 0; c < 3; ++c)
        momentum_of[3 * gifts[g].donor + c] +=
          returned[g] * outgoing[3 * gifts[g].taker + c];
    for (const unsigned int p : touched)
    {
      const double kept = std::max(system.mass[p] - mass_out[p], 0.0);
      if (returns_more_than_it_has(p))
        for (unsigned int c = 0; c < 3; ++c)
          system.velocity[3 * p + c] = outgoing[3 * p + c];
      else if (mass_in[p] > 0)
        for (unsigned int c = 0; c < 3; ++c)
          system.velocity[3 * p + c] =
            (kept * system.velocity[3 * p + c] + momentum_of[3 * p + c])
            / (kept + mass_in[p]);
      system.mass[p] += mass_in[p] - mass_out[p];
    }
    compact_gifts();
    for (const unsigned int p : region)
      in_region[p] = 0;
  }


  double
  MassBalancer::lambda_at_rest(const ParticleSystem &system, const unsigned int i)
  {
    const double m = system.mass[i];
    return m > 0 ? row(system, i) / m : std::numeric_limits<double>::infinity();
  }


  unsigned int
  MassBalancer::raise_particles(ParticleSystem &system, const double limit)
  {
    // As balance() does, over the changed particles only (in increasing order), from
    // the masses as they are: the cutter updates the lumped part of a mass and keeps
    // the part moved before (mass_shift).
    std::sort(to_check.begin(), to_check.end());
    to_check.erase(std::unique(to_check.begin(), to_check.end()), to_check.end());
    const std::size_t n_changed = to_check.size();
    for (const unsigned int p : to_check)
      touch(system, p);
    seen.resize(system.n_particles(), 0);
    unsigned int raised = 0;
    for (std::size_t k = 0; k < n_changed; ++k)
    {
      const unsigned int i = to_check[k];
      if (!(system.free[i] > 0)
          || !(lambda_at_rest(system, i) > bound_tolerance * target_lambda))
        continue;
      const double need  = row(system, i) / (target_lambda / (1 + 1e-6)) - system.mass[i];
      const double moved = borrow(
        system,
        [&](const unsigned int p, const auto &f)
        { for_each_neighbour(*system.mesh, p, f); },
        [&](const unsigned int j) { return row(system, j); },
        i,
        need,
        limit,
        reach,
        seen,
        spare,
        donors,
        ring_first,
        ring,
        [&](const unsigned int d, const double m)
        {
          touch(system, d);
          record_gift(d, i, m);
        });
      raised += moved > 0;
    }
    return raised;
  }


  void
  MassBalancer::record_changes(ParticleSystem &system, const double limit)
  {
    // Whether each particle is above the limit changes only where a mass or a row
    // changed: at the particles checked and those that gave or took back.
    for (const unsigned int p : touched)
    {
      const bool above =
        system.free[p] > 0 && lambda_at_rest(system, p) > bound_tolerance * limit;
      n_unresolved += static_cast<unsigned int>(above) - unresolved[p];
      unresolved[p] = above;
    }
    std::vector<unsigned int> changed;
    for (const unsigned int p : touched)
    {
      if (system.mass[p] == before_of[p])
        continue;
      positive_shift -= std::max(0.0, system.mass_shift[p]);
      system.mass_shift[p] += system.mass[p] - before_of[p];
      positive_shift += std::max(0.0, system.mass_shift[p]);
      changed.push_back(p);
    }
    if (!changed.empty())
      system.masses_changed(changed);
  }


  void
  MassBalancer::serialize(Archive &archive)
  {
    archive.section("mass balancer");
    archive(target_lambda, reach, positive_shift, n_unresolved, unresolved);
    archive(gifts, gifts_of, n_live_gifts);
  }
} // namespace lacerta::physics
