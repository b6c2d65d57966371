/**
 * @file
 * The common part of the integrators that evaluate the acceleration once per step.
 */
#pragma once

#include <lacerta/physics/integrator.h>
#include <lacerta/physics/particle_system.h>

#include <cstddef>
#include <vector>

namespace lacerta::physics
{
  /**
   * An integrator with one acceleration evaluation per step into one scratch vector
   * (symplectic Euler, velocity Verlet, explicit Euler), and no parameters of its own.
   */
  class SingleEvaluationIntegrator : public Integrator
  {
  public:
    /// These integrators have no parameters.
    static void
    declare_parameters(dealii::ParameterHandler &prm);

    /// Allocates the acceleration vector.
    void
    initialize(const ParticleSystem &system) override;

    /// One evaluation per step.
    unsigned int
    n_evaluations_per_step() const override;

    /// The accelerations of the last evaluation.
    void
    serialize(Archive &archive) override;

  protected:
    /**
     * Evaluates the accelerations at the system's state and, in the same parallel
     * pass, writes every coordinate's next position and velocity with
     * @p update(x, v, a, x_next, v_next) and puts the range's constrained particles
     * where the scene prescribes them at @p t + @p dt; then makes the next state the
     * system's.
     */
    template <typename Update>
    void
    advance(ParticleSystem &system, const double t, const double dt, const Update &update)
    {
      prepare_next_state(system);
      system.prepare_constraints(t + dt);
      const double *x = system.position.data(), *v = system.velocity.data();
      const double *a      = acceleration.data();
      double       *x_next = next_position.data(), *v_next = next_velocity.data();
      system.compute_acceleration(
        x,
        v,
        acceleration.data(),
        [=, &update, &system](const unsigned int begin, const unsigned int end)
        {
          for (std::size_t i = 3 * std::size_t(begin); i < 3 * std::size_t(end); ++i)
            update(x[i], v[i], a[i], x_next[i], v_next[i]);
          system.prescribe_constraints(x_next, v_next, begin, end);
        });
      take_next_state(system);
    }

    /**
     * Sizes the next state's buffers like the system's positions and velocities, for
     * an update that writes the next state while other threads may still read the
     * current one (see RangeUpdate).
     */
    void
    prepare_next_state(const ParticleSystem &system);

    /// Makes the next state the system's positions and velocities (a swap, no copy).
    void
    take_next_state(ParticleSystem &system);

    /// Accelerations of the current evaluation, 3 per particle.
    std::vector<double> acceleration;

    /// The next positions and velocities, 3 per particle (scratch of one step).
    std::vector<double> next_position, next_velocity;
  };
} // namespace lacerta::physics
