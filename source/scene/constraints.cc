// Constraint plugins: fixed, moving handle, force handle.

#include <lacerta/base/exceptions.h>
#include <lacerta/base/parameter_utilities.h>
#include <lacerta/physics/particle_system.h>
#include <lacerta/scene/constraint.h>

#include <deal.II/base/function_parser.h>
#include <deal.II/lac/vector.h>

namespace lacerta::scene
{
  namespace
  {
    /**
     * Particles held at their rest positions.
     */
    class Fixed : public Constraint
    {
    public:
      static void
      declare_parameters(dealii::ParameterHandler &)
      {
      }

      void
      parse_parameters(dealii::ParameterHandler &) override
      {
      }

      bool
      prescribes_motion() const override
      {
        return true;
      }

      void
      prescribe(double, const double *rest, double *x, double *v) const override
      {
        for (const unsigned int i : particles)
          for (unsigned int d = 0; d < 3; ++d)
          {
            x[3 * i + d] = rest[3 * i + d];
            v[3 * i + d] = 0.0;
          }
      }
    };


    /**
     * Particles moved by a prescribed displacement u(x, y, z, t) of their rest
     * position: a pulling handle (Figure 8's cubes), a clamp that turns, a probe.
     */
    class MovingHandle : public Constraint
    {
    public:
      static void
      declare_parameters(dealii::ParameterHandler &prm)
      {
        prm.declare_entry(
          "Displacement",
          "0; 0; 0",
          dealii::Patterns::Anything(),
          "Displacement u(x, y, z, t) [m] of a particle from its rest "
          "position (x, y, z) at time t: three expressions separated by ';'. "
          "The velocity is its time derivative (central differences).");
      }

      void
      parse_parameters(dealii::ParameterHandler &prm) override
      {
        displacement =
          parse_vector_expression("Constraints", "Displacement", prm.get("Displacement"));
      }

      bool
      prescribes_motion() const override
      {
        return true;
      }

      void
      prescribe(const double t, const double *rest, double *x, double *v) const override
      {
        const double h = 1e-7 * std::max(1.0, std::abs(t));
        for (const unsigned int i : particles)
        {
          const dealii::Point<3> p(rest[3 * i], rest[3 * i + 1], rest[3 * i + 2]);
          for (unsigned int d = 0; d < 3; ++d)
          {
            displacement->set_time(t);
            x[3 * i + d] = rest[3 * i + d] + displacement->value(p, d);
            displacement->set_time(t + h);
            const double ahead = displacement->value(p, d);
            displacement->set_time(t - h);
            v[3 * i + d] = (ahead - displacement->value(p, d)) / (2 * h);
          }
        }
      }

    private:
      std::unique_ptr<dealii::FunctionParser<3>> displacement;
    };


    /**
     * A total force F(t) on the region, shared among its particles in proportion to
     * their masses (so it accelerates the region uniformly).
     */
    class ForceHandle : public Constraint
    {
    public:
      static void
      declare_parameters(dealii::ParameterHandler &prm)
      {
        prm.declare_entry("Force",
                          "0; 0; 0",
                          dealii::Patterns::Anything(),
                          "Total force F(t) [N] on the region: three expressions of t "
                          "separated by ';' (x, y, z are the region's rest centroid).");
      }

      void
      parse_parameters(dealii::ParameterHandler &prm) override
      {
        force = parse_vector_expression("Constraints", "Force", prm.get("Force"));
      }

      bool
      prescribes_motion() const override
      {
        return false;
      }

      void
      initialize(const std::vector<unsigned int> &selected,
                 physics::ParticleSystem         &system) override
      {
        Constraint::initialize(selected, system);
        total_mass = 0;
        centroid   = dealii::Point<3>();
        for (const unsigned int i : particles)
        {
          total_mass += system.mass[i];
          for (unsigned int d = 0; d < 3; ++d)
            centroid[d] += system.rest_position()[3 * i + d] / particles.size();
        }
      }

      void
      add_forces(const double t, physics::ParticleSystem &system) const override
      {
        force->set_time(t);
        dealii::Vector<double> value(3);
        force->vector_value(centroid, value);
        for (const unsigned int i : particles)
          for (unsigned int d = 0; d < 3; ++d)
            system.external_force[3 * i + d] += value[d] * system.mass[i] / total_mass;
      }

    private:
      std::unique_ptr<dealii::FunctionParser<3>> force;
      dealii::Point<3>                           centroid;
      double                                     total_mass = 0;
    };
  } // namespace

  LACERTA_REGISTER_CONSTRAINT(Fixed,
                              "fixed",
                              "The region's particles stay at their rest positions.");
  LACERTA_REGISTER_CONSTRAINT(
    MovingHandle,
    "moving handle",
    "The region's particles follow a prescribed displacement "
    "u(x, y, z, t) ('subsection Moving handle'), e.g. a cube that "
    "pulls the tissue.");
  LACERTA_REGISTER_CONSTRAINT(ForceHandle,
                              "force handle",
                              "A total force F(t) on the region, shared by mass "
                              "('subsection Force handle').");
} // namespace lacerta::scene
