/**
 * @file
 * The stability bound kept per particle and updated where the system changed.
 */
#pragma once

#include <lacerta/physics/stability.h>

#include <optional>
#include <vector>

namespace lacerta
{
  class Archive;
}
namespace lacerta::physics
{
  class ParticleSystem;

  /**
   * The bound of bound_highest_frequency(), kept per particle
   * with the weights of its rows so that a local change of the system (a cut, a tear)
   * costs a bound over the changed particles' stars, not over the whole system:
   * nothing global per cut.
   *
   * Between two compute(), a particle's bound is that of the positions it was last
   * computed at, as the bound of bound_highest_frequency() is that of the positions
   * it was called at.
   */
  class StabilityBound
  {
  public:
    /// Computes the bound at every particle, at the current positions.
    void
    compute(const ParticleSystem &system);

    /**
     * The highest bound over the particles at the current positions with the row
     * weights kept from the last compute() or update(), without keeping it: any
     * positive weights bound the same matrix (weighted_frequency_bounds()), so this
     * holds at the current positions and is at least what compute() would give there,
     * at a third of its cost (the weights are not chosen again). Empty if compute()
     * was never called or the number of particles changed since.
     */
    std::optional<FrequencyBound>
    bound_with_kept_weights(const ParticleSystem &system) const;

    /**
     * Whether the bound with the kept row weights at the current positions (that of
     * bound_with_kept_weights()) is at most @p squared_omega (rad²/s²) at every
     * particle: false also if a row is not a number, or if compute() was never called
     * or the number of particles changed since. The answer is always that of the
     * highest row, but for a force model of springs only most rows are settled
     * without being bounded (doc/stability.md, "Blow-up detection"): against the
     * positions and rows of the last check that bounded every row, by one pass over
     * the springs that finds those that collapsed below half their rest length or
     * whose ends moved past their allowance (spring_motion_allowances()). Only the
     * rows at those springs are bounded at the current positions (gershgorin_rows()),
     * unless they are more than a quarter of the particles: then every row is
     * (weighted_frequency_bounds_at()), and the positions become the reference.
     */
    bool
    kept_weights_within(const ParticleSystem &system, double squared_omega);

    /**
     * Updates the bound after a local change of the system: the particles listed in
     * @p changed (ParticleSystem::changed_particles(), repeats allowed) and the
     * appended ones get new weights (gershgorin_row_weight(), refined_row_weight()),
     * and they and their neighbours are bounded again at the current positions; the
     * others keep their bound and weights. Computes everything if the system has no
     * mesh with local updates whose edges are its springs, if every particle counts
     * as changed (ParticleSystem::all_particles_changed()), or if compute() was never
     * called.
     */
    void
    update(const ParticleSystem &system, const std::vector<unsigned int> &changed);

    /// The highest bound over the particles, and where it is (the first particle
    /// among equals).
    FrequencyBound
    bound() const;

    /// The squared bound λ_i = ω_i² kept for particle @p i (rad²/s²).
    double
    squared_frequency(const unsigned int i) const
    {
      return lambda[i];
    }

    /// The weight d_i of every particle's row (weighted_frequency_bounds()).
    const std::vector<double> &
    row_weights() const
    {
      return weights;
    }

    /// Writes or reads the state for a checkpoint (see lacerta::Archive).
    void
    serialize(Archive &archive);

  private:
    /// Builds the tree of maxima over `lambda`, with room for at least @p n
    /// particles.
    void
    build_tree(unsigned int n);

    /// Whether the rows of @p system can be bounded locally: it has a mesh with local
    /// updates whose edges are its springs (gershgorin_rows() walks their stars).
    static bool
    has_local_rows(const ParticleSystem &system);

    /// Bounds the particles in `rows` at the current positions into `row_lambda` and
    /// `row_spring`, the first @p n_reweighted with new weights (gershgorin_rows()).
    void
    bound_rows(const ParticleSystem &system, std::size_t n_reweighted);

    /// Bounds every row at the current positions with the kept weights: whether all
    /// are at most @p squared_omega; keeps them as the check's reference if so.
    bool
    rows_within(const ParticleSystem &system, double squared_omega);

    /// Appends particle @p p to `rows` unless it holds it (marked with `mark`).
    void
    add_row(unsigned int p);

    /// Appends to `rows` particle @p p and the vertices of its star that it does not
    /// hold yet.
    void
    add_star(const ParticleSystem &system, unsigned int p);

    /// Sets particle @p i's bound and updates the tree of maxima above it.
    void
    set(unsigned int i, double squared_omega, unsigned int spring);

    /// Whether particle @p a's bound beats @p b's (higher, or equal and first).
    bool
    beats(unsigned int a, unsigned int b) const;

    /// λ_i = ω_i² and the stiffest spring of every particle.
    std::vector<double>       lambda;
    std::vector<unsigned int> stiffest;
    /// The first weight of every particle's row, gershgorin_row_weight() of its row
    /// with all weights 1, and its weight, refined_row_weight() of its row with the
    /// first weights.
    std::vector<double> first_weights, weights;
    /// A tree of maxima: node k holds the best particle of its two children, the
    /// leaves (from `leaves` on) the particles; `none` past the last particle.
    std::vector<unsigned int>     tree;
    unsigned int                  leaves = 0;
    static constexpr unsigned int none   = static_cast<unsigned int>(-1);

    /// The rows of an update (the changed particles and their neighbours) or of a
    /// periodic check (the ends of the springs it bounds again), marked in `row_mark`
    /// with the call's `mark`.
    std::vector<unsigned int> rows, row_mark;
    unsigned int              mark = 0;
    /**
     * What kept_weights_within() settles rows with, for a force model of springs
     * only: the isotropic_frequency_bounds() with `weights`; the positions and rows of
     * the last check that bounded every row, and the allowance of each spring for
     * the limit `limit` (spring_motion_allowances()). Empty until a check needs them
     * after a compute(), update() or checkpoint.
     */
    struct CheckReference
    {
      std::vector<double> isotropic, position, rows, allowed;
      double              limit = 0;
      /// Forgets everything (the masses, springs or weights changed).
      void
      clear();
    };
    CheckReference check;
    /// The ends of the springs a check bounds again.
    std::vector<unsigned int> ends;
    /// The bounds and stiffest springs of `rows` (bound_rows()), and its scratch.
    std::vector<double>       row_lambda;
    std::vector<unsigned int> row_spring;
    GershgorinRowScratch      scratch;
  };
} // namespace lacerta::physics
