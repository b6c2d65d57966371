/**
 * @file
 * Mass redistribution after a topology change: keeps the explicit integrators' stable
 * time step where it was before a cut or a tear made small cells.
 */
#pragma once

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
   * square root, 1.41). A particle is raised only when the particles within reach can
   * spare all it needs: partial help would not lower the largest bound and would only
   * change the dynamics. Mass only moves along springs, so the mass of every connected
   * piece, and the total, stay ∫σ over it; a particle's velocity is kept. Every call
   * starts from the lumped masses (ParticleSystem::mass_shift records the difference).
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
    balance(ParticleSystem &system) const;

    /// The target: the bound on the highest eigenvalue ω² at rest (1/s²).
    double
    target() const
    {
      return target_lambda;
    }

    /// How far above the target a donor's bound may rise: a time step 1.41 times
    /// shorter at most, under the 1.5 times the cost per tetrahedron a cut may add.
    static constexpr double donor_headroom = 2.0;

  private:
    double       target_lambda;
    unsigned int reach;
  };
} // namespace lacerta::physics
