// Body force plugins: gravity, acceleration field.

#include <lacerta/base/exceptions.h>
#include <lacerta/base/parameter_utilities.h>
#include <lacerta/base/parsed_function.h>
#include <lacerta/physics/particle_system.h>
#include <lacerta/scene/body_force.h>

#include <deal.II/base/function_parser.h>

namespace lacerta::scene
{
  namespace
  {
    /**
     * A uniform, constant acceleration.
     */
    class Gravity : public BodyForce
    {
    public:
      static void
      declare_parameters(dealii::ParameterHandler &prm)
      {
        declare_point_entry(prm,
                            "Acceleration",
                            "0, 0, -9.81",
                            "Gravitational acceleration [m/s^2].");
      }

      void
      parse_parameters(dealii::ParameterHandler &prm) override
      {
        g = get_point(prm, "Acceleration");
      }

      void
      initialize(physics::ParticleSystem &system) override
      {
        for (unsigned int d = 0; d < 3; ++d)
          system.body_acceleration[d] += g[d];
      }

    private:
      std::array<double, 3> g{};
    };


    /**
     * An acceleration field b(x, y, z, t) evaluated at the particles' rest positions.
     */
    class AccelerationField : public BodyForce
    {
    public:
      static void
      declare_parameters(dealii::ParameterHandler &prm)
      {
        prm.declare_entry("Acceleration",
                          "0; 0; 0",
                          dealii::Patterns::Anything(),
                          "Acceleration b(x, y, z, t) [m/s^2] at rest position (x, y, z) "
                          "and time t: three expressions separated by ';'. Each particle "
                          "feels m b.");
      }

      void
      parse_parameters(dealii::ParameterHandler &prm) override
      {
        expression = prm.get("Acceleration");
        field      = parse_function("Body forces/Acceleration field/Acceleration",
                               expression,
                               3,
                               true);
      }

      bool
      varies() const override
      {
        return true;
      }

      void
      add_forces(const double t, physics::ParticleSystem &system) const override
      {
        field->set_time(t);
        const auto &rest = system.rest_position();
        for (unsigned int i = 0; i < system.n_particles(); ++i)
        {
          const dealii::Point<3> p(rest[3 * i], rest[3 * i + 1], rest[3 * i + 2]);
          for (unsigned int d = 0; d < 3; ++d)
            system.external_force[3 * i + d] += system.mass[i] * field->value(p, d);
        }
      }

    private:
      std::string                                expression;
      std::unique_ptr<dealii::FunctionParser<3>> field;
    };
  } // namespace

  LACERTA_REGISTER_BODY_FORCE(
    Gravity,
    "gravity",
    "A uniform gravitational acceleration ('subsection Gravity').");
  LACERTA_REGISTER_BODY_FORCE(
    AccelerationField,
    "acceleration field",
    "An acceleration b(x, y, z, t) that varies in space and time "
    "('subsection Acceleration field'); evaluated every step.");
} // namespace lacerta::scene
