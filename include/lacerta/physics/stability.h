/**
 * @file
 * Stability control: a bound on the highest eigenfrequency, and blow-up detection.
 */
#pragma once

#include <array>
#include <string>
#include <vector>

namespace lacerta
{
  class Archive;
}
namespace lacerta::physics
{
  class ParticleSystem;

  /**
   * An upper bound on the highest angular eigenfrequency of M⁻¹K and where it comes
   * from.
   */
  struct FrequencyBound
  {
    /// Bound on the highest angular eigenfrequency ω (rad/s); 0 if nothing moves.
    double omega = 0;
    /// The free particle whose Gershgorin disc gives the bound.
    unsigned int particle = 0;
    /// The stiffest spring (index into the system's springs) at that particle.
    unsigned int spring = 0;
  };

  /**
   * The parts of the block Gershgorin bound of bound_highest_frequency() that do not
   * depend on the masses, for the particles at @p positions (3 per particle): the bound
   * at a free particle i is diagonal[i] / m_i + Σ_e coupling[e] / sqrt(m_i m_j) over
   * its springs e = (i, j).
   */
  struct GershgorinTerms
  {
    /// λ_max(Σ_e K_e) over the springs at each particle.
    std::vector<double> diagonal;
    /// ||K_e|| of each spring whose ends are both free, 0 otherwise.
    std::vector<double> coupling;
    /// The stiffest spring at each particle.
    std::vector<unsigned int> stiffest_spring;
    /// The absolute value |K_e| = k n nᵀ + |g| (I - n nᵀ) of each spring's tangent
    /// stiffness (g its geometric stiffness), xx, yy, zz, xy, xz, yz.
    std::vector<std::array<double, 6>> spring_block;
    /// The sum of the force model's diagonal element blocks at each particle.
    std::vector<std::array<double, 6>> element_block;
    /// The norms of the force model's off-diagonal blocks on each spring's edge whose
    /// ends are both free, 0 otherwise.
    std::vector<double> element_coupling;
  };

  /**
   * The mass-independent terms of the Gershgorin bound with the tangent stiffness of
   * every spring of @p system at @p positions (3 per particle; the rest positions give
   * the bound of the undeformed system), scaled as the force model scales the springs,
   * plus the per-tetrahedron stiffness of the force model if it has one
   * (ForceModel::for_each_element_stiffness()): the diagonal blocks of each element
   * stiffness, and the norm of each off-diagonal block added to the spring of its edge.
   * A system without a force model is bounded by its springs as they are.
   */
  GershgorinTerms
  gershgorin_terms(const ParticleSystem &system, const double *positions);

  /**
   * The squared block Gershgorin row bounds λ_i = diagonal[i] / m_i
   * + Σ_e coupling[e] / sqrt(m_i m_j) from the system's Gershgorin @p terms (0 for
   * constrained or massless particles): the rows of particle_frequency_bounds(), and
   * the weights of the bound (gershgorin_row_weight()).
   */
  std::vector<double>
  squared_frequency_bounds(const ParticleSystem &system, const GershgorinTerms &terms);

  /**
   * The squared rows λ_i of the bound of bound_highest_frequency() with the positive
   * @p weights d (one per particle), from the system's Gershgorin @p terms (0 for
   * constrained or massless particles):
   *
   * λ_i = max(λ_max(S_i + E_i), λ_max(S_i - E_i)) / m_i
   *       + Σ_{e=(i,j), j free} e_e / sqrt(m_i m_j) · d_j / d_i,
   * S_i = Σ_{e=(i,j)} (1 + t_e) |K_e|,   t_e = sqrt(m_i / m_j) d_j / d_i (0 if j is
   * held),
   *
   * with |K_e| the springs' absolute tangent blocks, E_i the force model's diagonal
   * element blocks and e_e its off-diagonal norms (GershgorinTerms). A spring's share
   * of the quadratic form, ±(x_i - x_j)ᵀ K_e (x_i - x_j), is at most
   * (1 + t) x_iᵀ |K_e| x_i + (1 + 1/t) x_jᵀ |K_e| x_j for every t > 0, and an element's
   * cross terms ±2 x_iᵀ K_ij x_j at most ||K_ij|| (s x_i² + x_j² / s) for every s > 0;
   * so |xᵀ K x| ≤ Σ_i λ_i m_i |x_i|², and max_i λ_i bounds the largest eigenvalue of
   * M^-1/2 K M^-1/2 in magnitude for every choice of positive weights
   * (doc/stability.md): the highest frequency, and the fastest growth or decay of a
   * strongly compressed spring's negative stiffness, which the explicit schemes must
   * resolve as well.
   */
  std::vector<double>
  weighted_frequency_bounds(const ParticleSystem      &system,
                            const GershgorinTerms     &terms,
                            const std::vector<double> &weights);

  /**
   * weighted_frequency_bounds() with @p weights for the particles at @p positions, and
   * in @p stiffest_spring the stiffest spring at each particle (as
   * GershgorinTerms::stiffest_spring), without the springs' terms kept in between:
   * each thread range of the force model works out the terms of its own springs and
   * adds them to its rows. The same rows to the bit as gershgorin_terms() followed
   * by weighted_frequency_bounds() (the same stiffest spring unless two tie within
   * rounding), in one pass over the springs instead of three and no memory per
   * spring: the periodic check with kept weights
   * (StabilityBound::bound_with_kept_weights()).
   */
  std::vector<double>
  weighted_frequency_bounds_at(const ParticleSystem      &system,
                               const double              *positions,
                               const std::vector<double> &weights,
                               std::vector<unsigned int> &stiffest_spring);

  /**
   * Upper bounds of the rows of weighted_frequency_bounds_at() with @p weights that
   * hold at every positions where no spring is shorter than half its rest length, for
   * a force model of springs only (ForceModel::has_element_stiffness() false; throws
   * otherwise). There a spring's term |K_e| has the eigenvalues |k_e| (along the
   * spring) and |k_e (1 - L_e / l_e)| <= |k_e|, so row i is at most
   * Σ_e (1 + t_e) |k_e| / m_i, whatever the springs' directions: one pass over the
   * springs without a square root per spring, to be done again only when masses,
   * stiffnesses or weights change.
   */
  std::vector<double>
  isotropic_frequency_bounds(const ParticleSystem      &system,
                             const std::vector<double> &weights);

  /**
   * For the periodic check of a force model of springs only: how far (squared) the
   * ends of each spring may move relative to each other from @p reference positions
   * before the rows at its ends may exceed @p squared_omega (rad²/s²), given the rows
   * @p reference_rows of weighted_frequency_bounds_at() there and the
   * isotropic_frequency_bounds() @p isotropic with the same weights. While a spring is
   * at least half its rest length, its term |K_e| moves by at most 4 |k_e| ρ when its
   * ends moved by ρ of its reference length (doc/stability.md), so a row rises by at
   * most 4 ρ times its isotropic bound. Infinite where both ends' isotropic rows are
   * within the limit, negative where a reference row is not below it.
   */
  std::vector<double>
  spring_motion_allowances(const ParticleSystem      &system,
                           const double              *reference,
                           const std::vector<double> &reference_rows,
                           const std::vector<double> &isotropic,
                           double                     squared_omega);

  /**
   * Appends to @p ends both ends of every spring whose rows the periodic check must
   * bound again at @p positions: shorter than half its rest length (or of a length
   * that is not a number), or whose ends moved relative to each other since
   * @p reference by more than its allowance @p allowed (spring_motion_allowances()).
   * One pass over the springs without a square root.
   */
  void
  append_ends_of_springs_to_bound_again(const ParticleSystem      &system,
                                        const double              *positions,
                                        const double              *reference,
                                        const std::vector<double> &allowed,
                                        std::vector<unsigned int> &ends);

  /**
   * The weight d_i of a row for weighted_frequency_bounds(), from its block Gershgorin
   * bound with all weights 1 (squared_frequency_bounds()), @p unscaled_row: that bound
   * itself (1 if it is 0, for a particle without a row; a NaN stays NaN, so that the
   * bound reports it). Where the rows differ, the heavy, slow particles next to a
   * light, fast one then take a share of its coupling terms in proportion to how much
   * lower their rows are: for a light particle on one spring to a heavy one, the
   * weighted rows are the exact frequency.
   * A property of a row and its neighbours' rows only, so a local change of the
   * system changes the weights locally (StabilityBound::update()).
   */
  inline double
  gershgorin_row_weight(const double unscaled_row)
  {
    return unscaled_row == 0 ? 1.0 : unscaled_row;
  }

  /// gershgorin_row_weight() of every particle, from the system's Gershgorin @p terms.
  std::vector<double>
  gershgorin_row_weights(const ParticleSystem &system, const GershgorinTerms &terms);

  /**
   * The weight of a row one power step on from weight @p weight, at which the row of
   * weighted_frequency_bounds() is @p weighted_row: their product (1 for a particle
   * without a row; a NaN stays NaN). With d the first weights (gershgorin_row_weight(),
   * the rows of |A| times the vector of ones, for A = M^-1/2 K M^-1/2), this is about
   * |A| d: the next step of the power iteration towards the eigenvector of the highest
   * frequency, whose weights make the bound exact. Like the first weights, a property
   * of a row and its neighbours' (first) weights, so local.
   */
  inline double
  refined_row_weight(const double weighted_row, const double weight)
  {
    return gershgorin_row_weight(weighted_row * weight);
  }

  /// refined_row_weight() of every particle from the rows of
  /// weighted_frequency_bounds() with @p weights, from the system's Gershgorin
  /// @p terms: the weights of bound_highest_frequency() from those of
  /// gershgorin_row_weights().
  std::vector<double>
  refined_row_weights(const ParticleSystem      &system,
                      const GershgorinTerms     &terms,
                      const std::vector<double> &weights);

  /**
   * Working space of gershgorin_rows() and gershgorin_row_sums(), kept between calls so
   * that a local update allocates nothing once it has grown: marks per particle, spring
   * and tetrahedron, and the terms of the rows being computed.
   */
  struct GershgorinRowScratch
  {
    /// The call's mark; an array entry equal to it belongs to the current call.
    unsigned int              stamp = 0;
    std::vector<unsigned int> row_stamp, row_of, spring_stamp, spring_of, tet_stamp;
    /// The tetrahedra around the rows and the springs at the rows (and room to sort
    /// them).
    std::vector<unsigned int>          tets, springs, sorted_springs;
    std::vector<std::array<double, 6>> blocks;
    std::vector<double>                pair_norm, off_diagonal, stiffest;
    /// The diagonal terms λ_max(Σ_e K_e) / m_i of the rows weighted anew.
    std::vector<double> diagonal;
    /// GershgorinTerms::element_block of the rows, spring_block and
    /// element_coupling (for held ends too) of the springs at the rows.
    std::vector<std::array<double, 6>> element_blocks, spring_blocks;
    std::vector<double>                element_norm;
    /// The blocks of the weighted rows being summed, and the weighted rows of the
    /// rows weighted anew with their first weights.
    std::vector<std::array<double, 6>> row_blocks;
    std::vector<double>                refined;
    /// sqrt(m_i) / d_i and 1 / (sqrt(m_i) d_i) of the rows being summed.
    std::vector<double> row_down, row_inverse;
  };

  /**
   * The squared row bounds λ_i of weighted_frequency_bounds() with @p weights (one per
   * particle) and the stiffest spring at the particles @p rows only (distinct), from
   * the springs and the force model's tetrahedra around them at positions @p x: into
   * @p lambda and @p stiffest_spring, one entry per row. The first @p n_reweighted
   * rows get their weights anew first: their first weights (gershgorin_row_weight() of
   * their rows with all weights 1) into @p first_weights, then their weights
   * (refined_row_weight() of their rows with the first weights) into @p weights; so
   * @p rows must hold every neighbour of those, whose rows read them.
   * The same values as the computation over the whole system with those weights, to
   * rounding, at a cost that depends on the rows' stars only. Needs `system.mesh`
   * with local updates (its edges are the springs).
   */
  void
  gershgorin_rows(const ParticleSystem            &system,
                  const double                    *x,
                  const std::vector<unsigned int> &rows,
                  std::size_t                      n_reweighted,
                  std::vector<double>             &first_weights,
                  std::vector<double>             &weights,
                  GershgorinRowScratch            &scratch,
                  double                          *lambda,
                  unsigned int                    *stiffest_spring);

  /**
   * The mass-independent row sums a_i + Σ_e c_e of gershgorin_terms() (λ_max of the
   * diagonal block plus ||K_e|| of every spring at i whose ends are both free) at the
   * particles @p rows only (distinct), at positions @p x, into @p row_sum, one entry per
   * row: what the row bound is before dividing by the particle's mass. At a cost that
   * depends on the rows' stars only; needs `system.mesh` as gershgorin_rows() does.
   */
  void
  gershgorin_row_sums(const ParticleSystem            &system,
                      const double                    *x,
                      const std::vector<unsigned int> &rows,
                      GershgorinRowScratch            &scratch,
                      double                          *row_sum);

  /**
   * Bounds the highest eigenvalue of M^-1/2 K M^-1/2 by the largest row of
   * weighted_frequency_bounds() over the free particles, with the weights of
   * refined_row_weights() from those of gershgorin_row_weights(), the tangent stiffness
   * of each spring at the current positions, K_e = k n nᵀ + k (1 - L0/L)(I - n nᵀ), whose
   * geometric part matters for strongly compressed springs, and the element stiffness
   * blocks of a force model per tetrahedron (gershgorin_terms()). Constrained particles
   * do not move and drop out.
   */
  FrequencyBound
  bound_highest_frequency(const ParticleSystem &system);

  /**
   * The block Gershgorin row bound of every particle with all weights 1 (rad/s; 0 for
   * constrained or massless ones): the highest frequency of the springs around it.
   */
  std::vector<double>
  particle_frequency_bounds(const ParticleSystem &system);

  /**
   * What multi-rate integration could save: the share of the spring evaluations of a
   * single-rate step (all springs at the step of the highest frequency) that remain if
   * every spring stepped at its own stable step, the single-rate step times the largest
   * power of two (up to 1024) that the frequency bounds at its two particles allow.
   * 1 means no saving; 0.25 means a quarter of the evaluations.
   */
  double
  multirate_evaluation_share(const ParticleSystem &system);

  /**
   * Describes spring @p s of @p system for messages: its particles, rest positions,
   * stiffness and length.
   */
  std::string
  describe_spring(const ParticleSystem &system, unsigned int s);

  /**
   * Watches a run for blow-ups: positions or velocities that are not finite, and
   * mechanical energy that grows beyond the work done on the system by prescribed
   * motions and external forces. check() throws a lacerta::Error that names the step,
   * the time and the place.
   */
  class BlowUpMonitor
  {
  public:
    /**
     * Starts watching @p system from its current state; @p tolerance is the allowed
     * energy excess relative to the system's energy scale.
     */
    BlowUpMonitor(const ParticleSystem &system, double tolerance);

    /**
     * Checks the current state after step @p step, at time @p time. Also accumulates
     * the work done by the loads since the last check.
     */
    void
    check(const ParticleSystem &system, unsigned int step, double time);

    /**
     * Continues watching after the particles and springs of the system were replaced
     * (a cut, a tear, a new level of detail, an MT update): checks the new state
     * against the ledger so far (a change that puts particles far off stops the run,
     * the message naming @p cause), then starts the ledger again from the new state,
     * keeping the largest energy seen as the scale.
     */
    void
    restart(const ParticleSystem &system,
            unsigned int          step,
            double                time,
            const std::string    &cause);

    /**
     * Continues watching after a local change of the system (a cut, a tear): checks
     * now that the particles @p changed (ParticleSystem::changed_particles()) have
     * finite states, the message naming @p cause, and leaves the rest of restart()
     * to the next check(): it compares the energy with the ledger across the changes
     * made since, names the first of them, and starts the ledger again. Costs
     * O(changed particles + new particles), nothing global per cut.
     */
    void
    note_local_change(const ParticleSystem            &system,
                      const std::vector<unsigned int> &changed,
                      unsigned int                     step,
                      double                           time,
                      const std::string               &cause);

    /// Work done on the system by prescribed motions and external forces so far (J).
    double
    input_work() const
    {
      return work;
    }

    /// Writes or reads the state for a checkpoint (see lacerta::Archive).
    void
    serialize(Archive &archive);

  private:
    /// Fills `load` with the force each load exerts on the particles at @p system's
    /// state.
    void
    compute_load_forces(const ParticleSystem &system);

    /// Throws if a position or velocity of the @p particles (all if nullptr) is not
    /// finite; @p after names a change or is empty.
    void
    check_finite(const ParticleSystem            &system,
                 const std::vector<unsigned int> *particles,
                 unsigned int                     step,
                 double                           time,
                 const std::string               &after) const;

    /// Throws if the energy exceeds the ledger by more than the tolerance; returns the
    /// state's energy scale (kinetic + elastic + |body force potential|).
    double
    check_energy(const ParticleSystem &system,
                 unsigned int          step,
                 double                time,
                 const std::string    &after) const;

    /// Starts the energy ledger (initial energy, work, loads) from the current state.
    void
    start_ledger(const ParticleSystem &system);

    /// What the first local change since the last check was, and when ("" if none).
    std::string pending_change;

    double              tolerance;
    double              initial_energy;
    double              energy_scale;
    double              energy_floor;
    double              work = 0;
    std::vector<double> previous_position;
    std::vector<double> previous_load;
    std::vector<double> load;
  };
} // namespace lacerta::physics
