// Constraint plugins: fixed, moving handle, force handle.

#include <lacerta/base/archive.h>
#include <lacerta/base/exceptions.h>
#include <lacerta/base/parsed_function.h>
#include <lacerta/physics/particle_system.h>
#include <lacerta/scene/constraint.h>

#include <deal.II/base/function_parser.h>
#include <deal.II/lac/vector.h>

#include <array>

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
      prescribe(const double      *rest,
                double            *x,
                double            *v,
                const unsigned int begin,
                const unsigned int end) const override
      {
        const auto [first, last] = particles_in(begin, end);
        for (std::size_t k = first; k < last; ++k)
        {
          const unsigned int i = particles[k];
          for (unsigned int d = 0; d < 3; ++d)
          {
            x[3 * i + d] = rest[3 * i + d];
            v[3 * i + d] = 0.0;
          }
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
        displacement      = parse_function("Constraints/Moving handle/Displacement",
                                      prm.get("Displacement"),
                                      3,
                                      true);
        rigid_translation = !uses_position(prm.get("Displacement"));
      }

      bool
      prescribes_motion() const override
      {
        return true;
      }

      void
      prepare(const double t, const double *rest) override
      {
        // One time level at a time: FunctionParser::set_time is not free, and this runs
        // at every step for every particle of the handle. A displacement that names
        // none of x, y and z is the same for every particle: evaluated once (each
        // evaluation of the parser looks its thread's copy up under a lock).
        const double      h                  = 1e-7 * std::max(1.0, std::abs(t));
        const std::size_t n                  = rigid_translation ? 1 : particles.size();
        const auto        for_each_component = [&](const double time, const auto &use)
        {
          displacement->set_time(time);
          for (std::size_t k = 0; k < n; ++k)
          {
            // A rigid translation reads no particle (the handle may have none left).
            dealii::Point<3> p;
            if (!rigid_translation)
            {
              const unsigned int i = particles[k];
              p = dealii::Point<3>(rest[3 * i], rest[3 * i + 1], rest[3 * i + 2]);
            }
            for (unsigned int d = 0; d < 3; ++d)
              use(3 * k + d, displacement->value(p, d));
          }
        };
        offset.resize(3 * n);
        velocity.resize(3 * n);
        for_each_component(t,
                           [&](const std::size_t c, const double u) { offset[c] = u; });
        // Central difference: the velocity holds u(t + h) until u(t - h) is known.
        for_each_component(t + h,
                           [&](const std::size_t c, const double u) { velocity[c] = u; });
        for_each_component(t - h,
                           [&](const std::size_t c, const double u)
                           { velocity[c] = (velocity[c] - u) / (2 * h); });
      }

      void
      prescribe(const double      *rest,
                double            *x,
                double            *v,
                const unsigned int begin,
                const unsigned int end) const override
      {
        const auto [first, last] = particles_in(begin, end);
        for (std::size_t k = first; k < last; ++k)
        {
          const unsigned int i    = particles[k];
          const std::size_t  from = rigid_translation ? 0 : 3 * k;
          for (unsigned int d = 0; d < 3; ++d)
          {
            x[3 * i + d] = rest[3 * i + d] + offset[from + d];
            v[3 * i + d] = velocity[from + d];
          }
        }
      }

    private:
      std::unique_ptr<dealii::FunctionParser<3>> displacement;
      /// The displacement and velocity prepare() evaluated, 3 per particle (one
      /// particle's for a rigid translation).
      std::vector<double> offset, velocity;
      /// Whether the displacement names none of x, y and z.
      bool rigid_translation = false;
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
        force =
          parse_function("Constraints/Force handle/Force", prm.get("Force"), 3, true);
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
        force->vector_value(centroid, value);
        for (const unsigned int i : particles)
          for (unsigned int d = 0; d < 3; ++d)
            system.external_force[3 * i + d] += value[d] * system.mass[i] / total_mass;
      }

      /// The particles, their total mass and their rest centroid.
      void
      serialize(Archive &archive) override
      {
        Constraint::serialize(archive);
        archive(centroid, total_mass);
      }

    private:
      std::unique_ptr<dealii::FunctionParser<3>> force;
      /// Scratch for the force value, allocated once: add_forces runs every step.
      mutable dealii::Vector<double> value = dealii::Vector<double>(3);
      dealii::Point<3>               centroid;
      double                         total_mass = 0;
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
