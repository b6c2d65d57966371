// Integrator `explicit_euler`: forward Euler, for comparison.

#include <lacerta/physics/particle_system.h>
#include <lacerta/physics/single_evaluation_integrator.h>

#include <cmath>
#include <cstddef>

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
        // Each thread updates its particles as soon as their accelerations are known.
        advance(system,
                t,
                dt,
                [dt](const double x,
                     const double v,
                     const double a,
                     double      &x_next,
                     double      &v_next)
                {
                  x_next = x + dt * v;
                  v_next = v + dt * a;
                });
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
