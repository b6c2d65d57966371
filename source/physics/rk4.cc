// Integrator `rk4`: the classical fourth-order Runge-Kutta method the paper uses.

#include <lacerta/base/archive.h>
#include <lacerta/physics/integrator.h>
#include <lacerta/physics/particle_system.h>
#include <lacerta/physics/system_ranges.h>

#include <cmath>
#include <vector>

namespace lacerta::physics
{
  namespace
  {
    /**
     * Classical RK4 on (x, v). Its stability region reaches 2√2 on the imaginary axis
     * (undamped oscillations) and about 2.785 on the negative real axis; for damped
     * systems we use 2.785 over the largest eigenvalue modulus, a bound inside the
     * region in every direction of the left half plane.
     */
    class Rk4 : public Integrator
    {
    public:
      static void
      declare_parameters(dealii::ParameterHandler &)
      {
      }

      void
      initialize(const ParticleSystem &system) override
      {
        // Every stage writes its arrays before reading them: growing them is enough,
        // and costs the new particles only (nothing global per cut).
        const std::size_t n = system.position.size();
        for (auto *v : {&x_stage, &v_stage, &a_stage, &dx_sum, &dv_sum})
          v->resize(n);
      }

      void
      step(ParticleSystem &system, const double t, const double dt) override
      {
        double *x = system.position.data();
        double *v = system.velocity.data();

        // Stage 1 at (x, v).
        system.compute_acceleration(x, v, a_stage.data());
        for_each_coordinate_range(system,
                                  [&](const std::size_t begin, const std::size_t end)
                                  {
                                    for (std::size_t i = begin; i < end; ++i)
                                    {
                                      dx_sum[i]  = v[i];
                                      dv_sum[i]  = a_stage[i];
                                      x_stage[i] = x[i] + 0.5 * dt * v[i];
                                      v_stage[i] = v[i] + 0.5 * dt * a_stage[i];
                                    }
                                  });
        // Stages 2 and 3 at the midpoint, with weights 2.
        for (const double to_next : {0.5 * dt, dt})
        {
          system.compute_acceleration(x_stage.data(), v_stage.data(), a_stage.data());
          for_each_coordinate_range(system,
                                    [&](const std::size_t begin, const std::size_t end)
                                    {
                                      for (std::size_t i = begin; i < end; ++i)
                                      {
                                        const double vs = v_stage[i];
                                        dx_sum[i] += 2.0 * vs;
                                        dv_sum[i] += 2.0 * a_stage[i];
                                        x_stage[i] = x[i] + to_next * vs;
                                        v_stage[i] = v[i] + to_next * a_stage[i];
                                      }
                                    });
        }
        // Stage 4 at the end of the step.
        system.compute_acceleration(x_stage.data(), v_stage.data(), a_stage.data());
        const double sixth = dt / 6.0;
        for_each_coordinate_range(system,
                                  [&](const std::size_t begin, const std::size_t end)
                                  {
                                    for (std::size_t i = begin; i < end; ++i)
                                    {
                                      x[i] += sixth * (dx_sum[i] + v_stage[i]);
                                      v[i] += sixth * (dv_sum[i] + a_stage[i]);
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
        if (c == 0)
          return 2.0 * std::sqrt(2.0) / omega;
        // |λ| of the highest mode: ω if underdamped, c/2 + sqrt(c²/4 - ω²) otherwise.
        const double modulus =
          (c < 2 * omega) ? omega : 0.5 * c + std::sqrt(0.25 * c * c - omega * omega);
        return 2.785 / modulus;
      }

      unsigned int
      n_evaluations_per_step() const override
      {
        return 4;
      }

      /// Nothing: every step starts from the positions and velocities alone.
      void
      serialize(Archive &) override
      {
      }

    private:
      std::vector<double> x_stage, v_stage, a_stage, dx_sum, dv_sum;
    };
  } // namespace

  LACERTA_REGISTER_INTEGRATOR(Rk4,
                              "rk4",
                              "Classical fourth-order Runge-Kutta (the paper's choice): "
                              "four force evaluations per step, stable up to "
                              "ω·dt < 2√2 without damping.");
} // namespace lacerta::physics
