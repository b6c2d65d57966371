// Integrator `symplectic_euler`: semi-implicit Euler, velocity first.

#include <lacerta/physics/particle_system.h>
#include <lacerta/physics/single_evaluation_integrator.h>

#include <cstddef>

namespace lacerta::physics
{
  namespace
  {
    /**
     * v += dt a(x, v); x += dt v. First order, symplectic: the energy of an undamped
     * system stays bounded for any stable step.
     */
    class SymplecticEuler : public SingleEvaluationIntegrator
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
                  v_next = v + dt * a;
                  x_next = x + dt * v_next;
                });
      }

      double
      critical_time_step(const double omega,
                         const double mass_damping,
                         const double spring_damping) const override
      {
        return symplectic_critical_time_step(
          omega, modal_damping(omega, mass_damping, spring_damping));
      }
    };
  } // namespace

  LACERTA_REGISTER_INTEGRATOR(
    SymplecticEuler,
    "symplectic_euler",
    "Semi-implicit Euler (velocity first, then position): one force "
    "evaluation per step, first order, symplectic, stable up to "
    "ω·dt < 2 without damping, kept below ω·dt = √2, its 4:1 nonlinear "
    "resonance.");
} // namespace lacerta::physics
