// Integrator `rk4`: the classical fourth-order Runge-Kutta method the paper uses.

#include <lacerta/base/archive.h>
#include <lacerta/physics/integrator.h>
#include <lacerta/physics/particle_system.h>

#include <array>
#include <cmath>
#include <cstddef>
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
        for (auto *v : {&x_stage[0],
                        &x_stage[1],
                        &v_stage[0],
                        &v_stage[1],
                        &a_stage,
                        &dx_sum,
                        &dv_sum})
          v->resize(n);
      }

      void
      step(ParticleSystem &system, const double t, const double dt) override
      {
        double      *x = system.position.data(), *v = system.velocity.data();
        const double half = 0.5 * dt, sixth = dt / 6.0;
        double      *a = a_stage.data(), *dx = dx_sum.data(), *dv = dv_sum.data();
        double      *x0 = x_stage[0].data(), *v0 = v_stage[0].data();
        double      *x1 = x_stage[1].data(), *v1 = v_stage[1].data();
        // Each thread updates its particles as soon as their accelerations are known.
        // A stage reads one pair of stage arrays and writes the other, since the other
        // threads may still read the state evaluated; the last stage evaluates at a
        // stage state, so it updates (x, v) in place.
        system.compute_acceleration(x,
                                    v,
                                    a,
                                    [=](const unsigned int begin, const unsigned int end)
                                    {
                                      for (std::size_t i = 3 * std::size_t(begin);
                                           i < 3 * std::size_t(end);
                                           ++i)
                                      {
                                        dx[i] = v[i];
                                        dv[i] = a[i];
                                        x0[i] = x[i] + half * v[i];
                                        v0[i] = v[i] + half * a[i];
                                      }
                                    });
        // Stages 2 and 3 (weights 2), at the midpoint, to the midpoint and to the end.
        const auto middle_stage =
          [&](const double *xs, const double *vs, double *x_to, double *v_to, double to)
        {
          system.compute_acceleration(
            xs,
            vs,
            a,
            [=](const unsigned int begin, const unsigned int end)
            {
              for (std::size_t i = 3 * std::size_t(begin); i < 3 * std::size_t(end); ++i)
              {
                dx[i] += 2.0 * vs[i];
                dv[i] += 2.0 * a[i];
                x_to[i] = x[i] + to * vs[i];
                v_to[i] = v[i] + to * a[i];
              }
            });
        };
        middle_stage(x0, v0, x1, v1, half);
        middle_stage(x1, v1, x0, v0, dt);
        // Stage 4 at the end of the step, which puts the range's constrained particles
        // where the scene prescribes them.
        system.prepare_constraints(t + dt);
        system.compute_acceleration(
          x0,
          v0,
          a,
          [=, &system](const unsigned int begin, const unsigned int end)
          {
            for (std::size_t i = 3 * std::size_t(begin); i < 3 * std::size_t(end); ++i)
            {
              x[i] += sixth * (dx[i] + v0[i]);
              v[i] += sixth * (dv[i] + a[i]);
            }
            system.prescribe_constraints(x, v, begin, end);
          });
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
      /// Two stage states (positions and velocities): a stage reads one, writes the
      /// other.
      std::array<std::vector<double>, 2> x_stage, v_stage;

      /// The stage's accelerations and the weighted sums of the stages' slopes.
      std::vector<double> a_stage, dx_sum, dv_sum;
    };
  } // namespace

  LACERTA_REGISTER_INTEGRATOR(Rk4,
                              "rk4",
                              "Classical fourth-order Runge-Kutta (the paper's choice): "
                              "four force evaluations per step, stable up to "
                              "ω·dt < 2√2 without damping.");
} // namespace lacerta::physics
