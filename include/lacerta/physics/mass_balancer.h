/**
 * @file
 * Mass redistribution after a topology change: keeps the explicit integrators' stable
 * time step where it was before a cut or a tear made small cells.
 */
#pragma once

#include <lacerta/physics/stability.h>

#include <cstdint>
#include <vector>

namespace lacerta
{
  class Archive;
}
namespace lacerta::mesh
{
  class TetMesh;
}
namespace lacerta::physics
{
  class ParticleSystem;

  /**
   * What MassBalancer::balance() did.
   */
  struct MassBalanceStatistics
  {
    /// Particles whose mass was raised.
    unsigned int raised = 0;
    /// Particles whose bound stays above `donor_headroom` times the target (too little
    /// mass within reach, e.g. a tiny piece cut off on its own).
    unsigned int unresolved = 0;
    /// Mass moved between particles, from the lumped masses ∫σ c_i (kg).
    double moved = 0;
  };

  /**
   * Bounds the highest eigenfrequency of a particle system at rest by moving mass
   * between particles of the same piece.
   *
   * A cut close to a vertex makes small cells there: the lumped masses ∫σ c_i of the
   * particles near the cut shrink with the cells' volume (ε³ for a cut at ε of an
   * edge), their springs' stiffness only with ε, so the local eigenfrequency grows like
   * 1/ε and the explicit integrators' critical time step falls like ε. balance() finds
   * the free particles whose row Gershgorin bound of M⁻¹K at rest,
   * [λ_max(Σ_e K_e) + Σ_e ||K_e||] / m_i (gershgorin_terms() at the rest positions;
   * it does not depend on the neighbours' masses), exceeds the target, the largest such
   * bound of the system when the balancer was made, and raises each one's mass to what
   * the target needs by taking it from free particles joined to it by springs (at most
   * `reach` springs away, nearest ring first). A donor gives at most half of what it
   * has above the mass that keeps its own bound at `donor_headroom` times the target,
   * so the bound rises by that factor at most (the critical time step falls by its
   * square root, 1.41). A particle is raised
   * only when the particles within reach can spare all it needs: partial help would not
   * lower the largest bound and would only change the dynamics. Mass only moves along
   * springs, so the mass of every connected piece, and the total, stay ∫σ over it; it
   * moves with the velocity of the particle it leaves, so momentum is kept and kinetic
   * energy cannot grow. balance() starts from the lumped masses, rebalance() from the
   * masses as they are, taking back the gifts near the change first
   * (ParticleSystem::mass_shift records the difference from the lumped masses).
   */
  class MassBalancer
  {
  public:
    /**
     * Takes the target from @p system as it is now (before any topology change): the
     * highest Gershgorin bound at rest over its free particles. Mass is taken from at
     * most @p reach springs away (at least 1).
     */
    MassBalancer(const ParticleSystem &system, unsigned int reach);

    /**
     * Raises the mass of every free particle of @p system whose bound at rest exceeds
     * the target (or whose mass is not positive), taking it from its neighbours.
     */
    MassBalanceStatistics
    balance(ParticleSystem &system);

    /**
     * After a local change of @p system (a cut or a tear): as balance(), but only the
     * particles in @p particles (those the change touched,
     * ParticleSystem::changed_particles()) are raised, from the masses as they are,
     * with mass from the particles within reach of them. Particles the change did not
     * touch keep their masses unless they give. The cost depends on the changed
     * particles' neighbourhoods, not on the system. Needs `system.mesh` (its edges are
     * the springs). The statistics are those of the whole system: the mass away from
     * the lumped masses and the particles above the donors' limit, kept up to date.
     */
    MassBalanceStatistics
    rebalance(ParticleSystem &system, const std::vector<unsigned int> &particles);

    /// The target: the bound on the highest eigenvalue ω² at rest (1/s²).
    double
    target() const
    {
      return target_lambda;
    }

    /// How far above the target a donor's bound may rise: a time step 1.41 times
    /// shorter at most, under the 1.5 times the cost per tetrahedron a cut may add.
    static constexpr double donor_headroom = 2.0;

    /// A bound counts as above the target (or the donors' limit) only past this factor
    /// of it: rounding in the rows does not raise a particle or flag it.
    static constexpr double bound_tolerance = 1 + 1e-9;

    /// Writes or reads the state for a checkpoint (see lacerta::Archive).
    void
    serialize(Archive &archive);

  private:
    double       target_lambda;
    unsigned int reach;
    /// Σ max(0, mass_shift) and the particles above the donors' limit, after the last
    /// call, with the per-particle flags.
    double                    positive_shift = 0;
    unsigned int              n_unresolved   = 0;
    std::vector<std::uint8_t> unresolved;
    /// Throws unless @p system has its mesh with local updates.
    static void
    require_mesh(const ParticleSystem &system);

    /// Mass @p mass moved from particle @p donor to @p taker: the ledger rebalance()
    /// takes gifts back from.
    void
    record_gift(unsigned int donor, unsigned int taker, double mass);

    /// A gift of mass between two particles (mass 0 once taken back).
    struct Gift
    {
      unsigned int donor, taker;
      double       mass;
    };
    std::vector<Gift>                      gifts;
    std::vector<std::vector<unsigned int>> gifts_of;
    /// Takers whose own gifts are taken back with theirs, the gifts taken back and
    /// their masses, the particles' momenta (rebalance()).
    std::vector<unsigned int> cascade, taken_back;
    std::vector<double>       returned, momentum_of, mass_in, mass_out, outgoing;
    /// The gifts taken back to particles that return more than they have, by donor.
    std::vector<unsigned int> deficit_gifts;
    /// The most Gauss-Seidel sweeps for the velocities those particles return with
    /// (rebalance()); they stop when no velocity changes by more than 1e-15 of the
    /// largest.
    static constexpr unsigned int max_velocity_sweeps = 1000;
    /// The mass each particle gains (or loses) by the gifts being taken back.
    std::vector<double> pending;
    unsigned int        n_live_gifts = 0;
    /// Rebuilds the ledger without the gifts taken back once they are most of it.
    void
    compact_gifts();

    /// rebalance(), stage 1: the particles to check (@p particles), the region within
    /// reach of them, their rows at rest.
    void
    start_rebalance(const ParticleSystem            &system,
                    const std::vector<unsigned int> &particles);
    /// Stage 2: takes back the gifts in the region, and those of takers that can no
    /// longer afford what they gave on (the donors' limit @p limit).
    void
    take_back_gifts(const ParticleSystem &system, double limit);
    /// Stage 3: the gifts taken back return to their donors, with mass and momentum.
    void
    return_gifts(ParticleSystem &system);
    /// Stage 4: raises the particles to check whose bound exceeds the target, from
    /// donors below @p limit; returns how many were raised.
    unsigned int
    raise_particles(ParticleSystem &system, double limit);
    /// Stage 5: the flags of the particles above @p limit, the mass shifts, and the
    /// system told which masses changed.
    void
    record_changes(ParticleSystem &system, double limit);
    /// Calls @p f(q) for every particle q joined to @p p by a spring (an edge of
    /// @p mesh), once each.
    template <typename F>
    void
    for_each_neighbour(const mesh::TetMesh &mesh, unsigned int p, const F &f);
    /// Notes that particle @p p's mass may change in this call (`touched`, with its
    /// mass before).
    void
    touch(const ParticleSystem &system, unsigned int p);
    /// Computes the rows at rest @p rows into `row_sum`.
    void
    compute_rows(const ParticleSystem &system, const std::vector<unsigned int> &rows);
    /// Particle @p j's row at rest, computed if this call has not yet.
    double
    row(const ParticleSystem &system, unsigned int j);
    /// Particle @p i's bound at rest with its mass as it is (infinite if not positive).
    double
    lambda_at_rest(const ParticleSystem &system, unsigned int i);

    /// Scratch of rebalance(), kept so that a local call allocates nothing once grown.
    std::vector<unsigned int> region, mark, to_check, touched, touched_mark;
    std::vector<double>       before_of;
    unsigned int              touched_stamp = 0;
    std::vector<std::uint8_t> in_region;
    std::vector<char>         seen;
    std::vector<double>       row_sum, spare;
    /// Which rows at rest rebalance() computed in this call (`row_known` equal to
    /// `row_stamp`), and the scratch of their computation.
    std::vector<unsigned int> row_known, single_row;
    std::vector<double>       row_values;
    unsigned int              row_stamp = 0;
    /// The donors of one borrowing, ring by ring: where each ring starts, the ring.
    std::vector<unsigned int> donors, ring_first, ring;
    unsigned int              stamp = 0;
    GershgorinRowScratch      scratch;
  };
} // namespace lacerta::physics
