/**
 * @file
 * Explicit time integrators (plugins).
 */
#pragma once

#include <lacerta/base/plugins.h>

#include <memory>
#include <string>
#include <vector>

namespace lacerta
{
  class Archive;
}
namespace lacerta::physics
{
  class ParticleSystem;

  /**
   * An explicit integrator advances a ParticleSystem by one step. It allocates its
   * scratch vectors in initialize(), never in step().
   */
  class Integrator
  {
  public:
    /// Kind name used in messages and in the documentation.
    static std::string
    plugin_kind()
    {
      return "integrator";
    }

    virtual ~Integrator() = default;

    /// Reads the plugin's parameters from its subsection.
    virtual void
    parse_parameters(dealii::ParameterHandler &prm);

    /**
     * Allocates scratch space for @p system; call again when the number of particles
     * changes (cuts) or the state was changed from outside (level of detail switch).
     */
    virtual void
    initialize(const ParticleSystem &system) = 0;

    /**
     * Advances positions and velocities of @p system from time @p t by @p dt; the
     * constrained particles are put where the scene prescribes them at t + dt.
     */
    virtual void
    step(ParticleSystem &system, double t, double dt) = 0;

    /**
     * The largest stable time step for a system whose highest angular eigenfrequency is
     * @p omega (rad/s), with particle damping @p mass_damping (1/s) and damping along
     * springs @p spring_damping (s). Zero if no time step is stable (doc/stability.md).
     */
    virtual double
    critical_time_step(double omega,
                       double mass_damping,
                       double spring_damping) const = 0;

    /// Number of acceleration evaluations per step (for throughput figures).
    virtual unsigned int
    n_evaluations_per_step() const = 0;

    /**
     * Writes or reads what the integrator carries from one step to the next, for a
     * checkpoint (see lacerta::Archive); scratch space that every step overwrites is
     * not part of it.
     */
    virtual void
    serialize(Archive &archive) = 0;

    /// Declares `subsection Integrator` with the `Scheme` selector.
    static void
    declare_parameters(dealii::ParameterHandler &prm);

    /// Creates the integrator selected in `subsection Integrator`.
    static std::unique_ptr<Integrator>
    create(dealii::ParameterHandler &prm);
  };

  /// The registry of integrators.
  using IntegratorRegistry = PluginRegistry<Integrator>;

  /**
   * The damping rate c + β ω² of the mode with angular frequency @p omega under
   * particle damping c and spring damping β.
   */
  double
  modal_damping(double omega, double mass_damping, double spring_damping);

  /**
   * The linear stability limit of symplectic Euler and velocity Verlet for an
   * oscillator with angular frequency @p omega and damping rate @p c:
   * dt < (sqrt(c² + 4ω²) - c) / ω² (2/ω without damping; doc/stability.md derives it).
   */
  double
  symplectic_linear_stability_limit(double omega, double c);

  /**
   * The step symplectic Euler and velocity Verlet are kept under: the linear limit,
   * and at most √2/ω, the step of their 4:1 nonlinear resonance (four steps per
   * numerical period), above which a nonlinear force model can pump energy into its
   * fastest mode although every linearised mode is stable (doc/stability.md).
   */
  double
  symplectic_critical_time_step(double omega, double c);

  /**
   * Gives @p buffer the size of @p state and at least its capacity, so that an
   * integrator that writes the next state into @p buffer and swaps the two keeps the
   * state's room to grow (ParticleSystem::reserve()): a cut that adds particles then
   * copies no array of the whole system.
   */
  void
  resize_like(std::vector<double> &buffer, const std::vector<double> &state);
} // namespace lacerta::physics

/// Registers an integrator plugin, e.g. LACERTA_REGISTER_INTEGRATOR(Rk4, "rk4", "...").
#define LACERTA_REGISTER_INTEGRATOR(classname, name, description) \
  LACERTA_REGISTER_PLUGIN(lacerta::physics::Integrator, classname, name, description)
