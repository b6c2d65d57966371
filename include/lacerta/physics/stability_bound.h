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

    /// The rows of an update (the changed particles and their neighbours), marked
    /// in `row_mark` with the update's `mark`.
    std::vector<unsigned int> rows, row_mark;
    unsigned int              mark = 0;
    std::vector<double>       row_lambda;
    std::vector<unsigned int> row_spring;
    GershgorinRowScratch      scratch;
  };
} // namespace lacerta::physics
