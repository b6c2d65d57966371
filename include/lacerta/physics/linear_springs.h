/**
 * @file
 * Force model `linear springs`: the paper's springs, f = k (|d| - L0) d/|d|.
 */
#pragma once

#include <lacerta/physics/force_model.h>
#include <lacerta/physics/particle_ranges.h>
#include <lacerta/physics/spring_set.h>

#include <array>
#include <vector>

namespace lacerta::physics
{
  /**
   * The paper's spring model with a flat, thread-partitioned spring loop; the springs'
   * stiffness may be scaled by a constant factor (volume springs rescale them).
   *
   * Particles are split into one contiguous range per thread (the mesh is numbered
   * along a space-filling curve, so a range is a compact region). A thread owns the
   * forces of its range: it evaluates the springs inside its range (writing both
   * ends) and the springs that cross into another range (writing only its own end).
   * Crossing springs are thus evaluated twice, but no thread ever writes another's
   * memory: no atomics, no locks, no reduction.
   *
   * Each range's inner and crossing springs are a segment of their own, kept in the
   * order of the system's springs, and every system spring knows which segments hold
   * its copies, so that a cut updates only the springs it changed (springs_changed()):
   * a copy whose segment stays is rewritten in place (found by bisection), the copies
   * that change range are moved, merged into each segment they leave or join in one
   * pass per change, removed springs are the last ones. The evaluation then
   * sums every particle's forces in the order a model made afresh on the same ranges
   * would: on one range the forces are those of initialize() to the last bit. New
   * particles join the last range; when the ranges' loads drift apart by more than a
   * tenth of the mean, the partition is made again.
   *
   * A spring between two particles whose motion is prescribed (ParticleSystem::free)
   * acts on no free particle, and is not part of the dynamical system: it is kept
   * apart, in a segment of its own that neither the forces nor the elastic energy
   * count. Clamped regions thus cost nothing per step, however finely they are
   * meshed. A particle's constraint must be set before its springs are placed
   * (initialize() and springs_changed() read them); one set later leaves its springs
   * counted, which changes nothing but the cost.
   */
  class LinearSprings : public ForceModel
  {
  public:
    /// Declares no parameters: the springs come from `subsection Material`.
    static void
    declare_parameters(dealii::ParameterHandler &prm);

    void
    initialize(const ParticleSystem &system, unsigned int n_threads) override;

    void
    springs_changed(const ParticleSystem            &system,
                    const std::vector<unsigned int> &changed) override;

    void
    masses_changed(const ParticleSystem            &system,
                   const std::vector<unsigned int> &particles) override;

    void
    compute_acceleration(const ParticleSystem &system,
                         const double         *x,
                         const double         *v,
                         double               *a,
                         RangeUpdate           update) const override;

    using ForceModel::compute_acceleration;

    void
    compute_spring_forces(const ParticleSystem &system,
                          const double         *x,
                          const double         *v,
                          double               *f) const override;

    double
    elastic_energy(const ParticleSystem &system, const double *x) const override;

    double
    spring_stiffness_scale() const override;

    const ParticleRanges &
    particle_ranges() const override;

  protected:
    /**
     * Zeroes the forces of range @p p's particles and adds the forces of its springs
     * (with damping along springs if the system has it).
     */
    void
    spring_forces_of_part(const ParticleSystem &system,
                          unsigned int          p,
                          const double         *x,
                          const double         *v,
                          double               *f) const;

    /// Sets the factor applied to every spring's stiffness (before initialize()).
    void
    set_stiffness_scale(double scale);

    /// The springs' partition into the threads' ranges.
    void
    serialize(Archive &archive) override;

    /// The particle ranges of the threads.
    ParticleRanges ranges;

  private:
    /// The springs of one range: inner (both ends in it) or crossing (end a in it).
    struct Segment
    {
      SpringSet set;
      /// The system spring of each entry.
      std::vector<unsigned int> origin;
    };

    /// The segments that hold a system spring's copies (up to two).
    using Holders = std::array<unsigned int, 2>;

    /// Where spring @p s is, or goes, in segment @p g (kept in the springs' order).
    std::size_t
    slot(unsigned int g, unsigned int s) const;

    /// Removes spring @p s's copy from segment @p g.
    void
    erase(unsigned int g, unsigned int s);

    /// Removes every copy of spring @p s.
    void
    unplace(unsigned int s);

    /**
     * Puts system spring @p s (as it is now) into the segments of its ranges: in
     * place where it already has a copy in that segment; copies it needs in other
     * segments, and the removal of its copies in segments it left, wait for
     * apply_pending().
     */
    void
    place(const ParticleSystem &system, unsigned int s);

    /// Takes out and puts in the copies place() left pending, one pass per segment
    /// that has any (in the springs' order), so that a change of many springs costs
    /// one merge per segment instead of one shift of the segment per spring.
    void
    apply_pending();

    /// A copy waiting to be put into a segment.
    struct PendingCopy
    {
      unsigned int s, from, to;
      double       stiffness, rest_length;
    };
    /// elastic_energy()'s sum per range (scratch, so that the statistics' energy at
    /// every step allocates nothing).
    mutable std::vector<double> part_energy;
    /// springs_changed()'s marks of the springs it listed, `listed_mark` for this
    /// change (scratch, not kept in a checkpoint).
    std::vector<unsigned int> listed_stamp;
    unsigned int              listed_mark = 0;
    /// Per segment: the springs whose copies leave it, and the copies that come.
    std::vector<std::vector<unsigned int>> pending_erase;
    std::vector<std::vector<PendingCopy>>  pending_insert;

    /// Whether the ranges' numbers of spring copies are so uneven that the ranges
    /// should be split again (ParticleRanges::unbalanced()).
    bool
    unbalanced() const;

    /// The last segment: the springs between two prescribed particles.
    unsigned int
    held_segment() const;

    /// Inner and crossing springs of range p: segments 2p and 2p + 1; the last
    /// segment holds the springs between two prescribed particles.
    std::vector<Segment> segments;
    /// The segments that hold each system spring's copies.
    std::vector<Holders> holders;
    /// The springs the model was last told of.
    std::size_t known_springs = 0;
    /// The factor applied to every spring's stiffness.
    double stiffness_scale = 1.0;
  };
} // namespace lacerta::physics
