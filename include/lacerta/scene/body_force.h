/**
 * @file
 * Body forces: gravity and general acceleration fields (plugins, `subsection Body
 * forces`).
 */
#pragma once

#include <lacerta/base/plugins.h>

#include <memory>
#include <vector>

namespace lacerta::physics
{
  class ParticleSystem;
}

namespace lacerta::scene
{
  /**
   * A body force acts on every free particle in proportion to its mass. Uniform and
   * constant ones go into the system's body acceleration once (no cost per step);
   * fields that vary go into the external forces at every step.
   */
  class BodyForce
  {
  public:
    /// Kind name used in messages and in the documentation.
    static std::string
    plugin_kind()
    {
      return "body force";
    }

    virtual ~BodyForce() = default;

    /// Reads the plugin's parameters from its subsection.
    virtual void
    parse_parameters(dealii::ParameterHandler &prm) = 0;

    /// Sets up the constant part of the force on @p system (called once).
    virtual void
    initialize(physics::ParticleSystem &system);

    /// Whether add_forces() must be called at every step.
    virtual bool
    varies() const;

    /// Adds the force at time @p t to the system's external forces.
    virtual void
    add_forces(double t, physics::ParticleSystem &system) const;

    /// Declares `subsection Body forces` with the list and every plugin's subsection.
    static void
    declare_parameters(dealii::ParameterHandler &prm);

    /// Creates the body forces listed in `subsection Body forces`.
    static std::vector<std::unique_ptr<BodyForce>>
    create(dealii::ParameterHandler &prm);
  };

  /// The registry of body forces.
  using BodyForceRegistry = PluginRegistry<BodyForce>;
} // namespace lacerta::scene

/// Registers a body force plugin.
#define LACERTA_REGISTER_BODY_FORCE(classname, name, description) \
  LACERTA_REGISTER_PLUGIN(lacerta::scene::BodyForce, classname, name, description)
