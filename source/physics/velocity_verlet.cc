// Integrator `velocity_verlet`: the second-order symplectic leapfrog.

#include <lacerta/base/archive.h>
#include <lacerta/physics/particle_system.h>
#include <lacerta/physics/single_evaluation_integrator.h>
#include <lacerta/physics/system_ranges.h>

#include <vector>

namespace lacerta::physics
{
  namespace
  {
    /**
     * Velocity Verlet: v½ = v + dt/2 a(x, v); x += dt v½; v = v½ + dt/2 a(x, v½).
     * The acceleration at the end of a step is reused at the start of the next, so a
     * step costs one evaluation; velocity-dependent forces (damping) are evaluated with
     * the half-step velocity.
     */
    class VelocityVerlet : public SingleEvaluationIntegrator
    {
    public:
      static void
      declare_parameters(dealii::ParameterHandler &)
      {
      }

      void
      initialize(const ParticleSystem &system) override
      {
        SingleEvaluationIntegrator::initialize(system);
        acceleration_is_current = false;
      }

      void
      step(ParticleSystem &system, const double t, const double dt) override
      {
        double *x = system.position.data();
        double *v = system.velocity.data();
        if (!acceleration_is_current)
          system.compute_acceleration(x, v, acceleration.data());
        for_each_coordinate_range(system,
                                  [&](const std::size_t begin, const std::size_t end)
                                  {
                                    for (std::size_t i = begin; i < end; ++i)
                                    {
                                      v[i] += 0.5 * dt * acceleration[i];
                                      x[i] += dt * v[i];
                                    }
                                  });
        // Constrained particles must be in place before the new forces are computed.
        system.enforce_constraints(t + dt, x, v);
        // Each thread kicks its particles as soon as their accelerations are known,
        // into the next velocities: the other threads may still read these.
        resize_like(next_velocity, system.velocity);
        const double *a      = acceleration.data();
        double       *v_next = next_velocity.data();
        system.compute_acceleration(x,
                                    v,
                                    acceleration.data(),
                                    [=](const unsigned int begin, const unsigned int end)
                                    {
                                      for (std::size_t i = 3 * std::size_t(begin);
                                           i < 3 * std::size_t(end);
                                           ++i)
                                        v_next[i] = v[i] + 0.5 * dt * a[i];
                                    });
        system.velocity.swap(next_velocity);
        system.enforce_constraints(t + dt, x, system.velocity.data());
        acceleration_is_current = true;
      }

      double
      critical_time_step(const double omega,
                         const double mass_damping,
                         const double spring_damping) const override
      {
        return symplectic_critical_time_step(
          omega, modal_damping(omega, mass_damping, spring_damping));
      }


      /// The accelerations at the current positions, and whether they are current.
      void
      serialize(Archive &archive) override
      {
        SingleEvaluationIntegrator::serialize(archive);
        archive &acceleration_is_current;
      }

      bool acceleration_is_current = false;
    };
  } // namespace

  LACERTA_REGISTER_INTEGRATOR(
    VelocityVerlet,
    "velocity_verlet",
    "Velocity Verlet (leapfrog): one force evaluation per step, "
    "second order, symplectic, stable up to ω·dt < 2 without "
    "damping, kept below ω·dt = √2, its 4:1 nonlinear resonance.");
} // namespace lacerta::physics
