// Integrator `symplectic_euler`: semi-implicit Euler, velocity first.

#include <lacerta/physics/particle_system.h>
#include <lacerta/physics/single_evaluation_integrator.h>
#include <lacerta/physics/system_ranges.h>

#include <vector>

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
        double *x = system.position.data();
        double *v = system.velocity.data();
        system.compute_acceleration(x, v, acceleration.data());
        for_each_coordinate_range(system,
                                  [&](const std::size_t begin, const std::size_t end)
                                  {
                                    for (std::size_t i = begin; i < end; ++i)
                                    {
                                      v[i] += dt * acceleration[i];
                                      x[i] += dt * v[i];
                                    }
                                  });
        system.enforce_constraints(t + dt, x, v);
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
