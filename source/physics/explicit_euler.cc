// Integrator `explicit_euler`: forward Euler, for comparison.

#include <lacerta/physics/particle_system.h>
#include <lacerta/physics/single_evaluation_integrator.h>
#include <lacerta/physics/system_ranges.h>

#include <cmath>
#include <vector>

namespace lacerta::physics
{
  namespace
  {
    /**
     * x += dt v; v += dt a(x, v) from the old state. It amplifies every undamped
     * oscillation by sqrt(1 + ω²dt²) per step, so it is stable only with damping:
     * for an underdamped mode |1 + λ dt| < 1 gives dt < c/ω²; for an overdamped one
     * dt < 2/|λ|.
     */
    class ExplicitEuler : public SingleEvaluationIntegrator
    {
    public:
      static void
      declare_parameters(dealii::ParameterHandler &)
      {
      }


      void
      step(ParticleSystem &system, const double t, const double dt) override
      {
        double *x = system.position.data();
        double *v = system.velocity.data();
        system.compute_acceleration(x, v, acceleration.data());
        for_each_coordinate_range(system,
                                  [&](const std::size_t begin, const std::size_t end)
                                  {
                                    for (std::size_t i = begin; i < end; ++i)
                                    {
                                      x[i] += dt * v[i];
                                      v[i] += dt * acceleration[i];
                                    }
                                  });
        system.enforce_constraints(t + dt, x, v);
      }

      double
      critical_time_step(const double omega,
                         const double mass_damping,
                         const double spring_damping) const override
      {
        const double c = modal_damping(omega, mass_damping, spring_damping);
        if (c < 2 * omega)
          return c / (omega * omega);
        return 2.0 / (0.5 * c + std::sqrt(0.25 * c * c - omega * omega));
      }
    };
  } // namespace

  LACERTA_REGISTER_INTEGRATOR(
    ExplicitEuler,
    "explicit_euler",
    "Forward Euler: one force evaluation per step, first order; "
    "unstable without damping (every undamped mode grows), so it "
    "needs 'Mass damping' or 'Spring damping' > 0.");
} // namespace lacerta::physics
