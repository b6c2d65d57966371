/**
 * @file
 * Force models: how springs turn positions and velocities into forces (plugins).
 */
#pragma once

#include <lacerta/base/plugins.h>
#include <lacerta/physics/range_update.h>

#include <array>
#include <functional>
#include <memory>
#include <string>
#include <vector>

namespace lacerta
{
  class Archive;
}
namespace lacerta::physics
{
  class ParticleRanges;
  class ParticleSystem;

  /**
   * A force model evaluates the spring forces of a ParticleSystem. Implementations keep
   * their own flat, thread-partitioned copy of the springs (made by initialize()), so
   * the evaluation is one loop without virtual calls per spring.
   */
  class ForceModel
  {
  public:
    /// Kind name used in messages and in the documentation.
    static std::string
    plugin_kind()
    {
      return "force model";
    }

    virtual ~ForceModel() = default;

    /// Reads the plugin's parameters from its subsection.
    virtual void
    parse_parameters(dealii::ParameterHandler &prm);

    /**
     * Prepares the evaluation for the system's current springs on @p n_threads threads
     * (a new system or level of detail). A local change of the springs (a cut, a tear)
     * is passed to springs_changed() instead.
     */
    virtual void
    initialize(const ParticleSystem &system, unsigned int n_threads) = 0;

    /**
     * The springs of @p system changed locally since the model last saw them: the
     * springs listed in @p changed (indices into `system.springs`, appended ones
     * included; an index may be listed more than once) were added, moved into a
     * retired slot or given another stiffness; the slots from `system.springs.size()`
     * up to the count the model last saw were removed; particles may have been
     * appended. The masses that changed are those of new particles and of the ends of
     * the changed springs. Costs O(changed.size()) amortised, whatever the system's
     * size: nothing global per cut.
     */
    virtual void
    springs_changed(const ParticleSystem            &system,
                    const std::vector<unsigned int> &changed) = 0;

    /**
     * The masses of @p particles changed (nothing else did): whatever the model keeps
     * of them is updated. Costs O(particles.size()).
     */
    virtual void
    masses_changed(const ParticleSystem            &system,
                   const std::vector<unsigned int> &particles) = 0;

    /**
     * Accelerations: spring forces plus the system's loads and particle damping,
     * divided by the masses, zero for constrained particles. Then @p update runs for
     * every thread range's particles, on that range's thread, as soon as their
     * accelerations are complete (see RangeUpdate).
     */
    virtual void
    compute_acceleration(const ParticleSystem &system,
                         const double         *x,
                         const double         *v,
                         double               *a,
                         RangeUpdate           update) const = 0;

    /// Accelerations, as above, with no update.
    void
    compute_acceleration(const ParticleSystem &system,
                         const double         *x,
                         const double         *v,
                         double               *a) const;

    /**
     * Spring forces (including damping along springs) on every particle. A model may
     * leave out the springs (and elements) between prescribed particles only, which
     * act on no free particle (as `linear springs` does): the forces on free
     * particles are complete, and those on prescribed particles are the reactions of
     * the free material.
     */
    virtual void
    compute_spring_forces(const ParticleSystem &system,
                          const double         *x,
                          const double         *v,
                          double               *f) const = 0;

    /// Elastic energy stored in the springs (and elements) at positions @p x, but
    /// for those compute_spring_forces() leaves out.
    virtual double
    elastic_energy(const ParticleSystem &system, const double *x) const = 0;

    /**
     * The factor the model applies to the stiffness of the system's springs: 1 for the
     * paper's springs, 0 for a model without springs. The stability bound scales the
     * springs' terms by it.
     */
    virtual double
    spring_stiffness_scale() const;

    /// Writes or reads the model's state for a checkpoint (see lacerta::Archive).
    virtual void
    serialize(Archive &archive) = 0;

    /**
     * The particle ranges the model's threads work in (made by initialize() for its
     * thread count, extended by springs_changed()). Work over the whole system that
     * is not the model's own (the stability bound's periodic check) runs in them, on
     * the same threads.
     */
    virtual const ParticleRanges &
    particle_ranges() const = 0;

    /**
     * Whether the model has a per-tetrahedron term besides the springs (what
     * for_each_element_stiffness() visits): false for a model of springs only, whose
     * stability bound then depends on the positions through the springs alone.
     */
    virtual bool
    has_element_stiffness() const;

    /// A 12x12 tangent stiffness of a tetrahedron, rows and columns ordered (local
    /// vertex, component), row-major.
    using ElementStiffness = std::array<double, 144>;

    /**
     * Calls @p visit(t, K) for every tetrahedron t of `system.mesh` with the tangent
     * stiffness K of the model's per-tetrahedron term at positions @p x (what the
     * stability bound adds to the springs' terms). A model of springs only visits
     * nothing.
     */
    virtual void
    for_each_element_stiffness(
      const ParticleSystem                                              &system,
      const double                                                      *x,
      const std::function<void(unsigned int, const ElementStiffness &)> &visit) const;

    /**
     * Calls @p visit(t, K) as for_each_element_stiffness() does, for the tetrahedra
     * listed in @p tets only (in that order; a tetrahedron listed twice is visited
     * twice): what a local update of the stability bound needs after a cut. A model
     * of springs only visits nothing.
     */
    virtual void
    for_each_element_stiffness_of(
      const ParticleSystem                                              &system,
      const double                                                      *x,
      const std::vector<unsigned int>                                   &tets,
      const std::function<void(unsigned int, const ElementStiffness &)> &visit) const;

    /// Declares `subsection Force model` with the `Model` selector.
    static void
    declare_parameters(dealii::ParameterHandler &prm);

    /// Creates the model selected in `subsection Force model`.
    static std::unique_ptr<ForceModel>
    create(dealii::ParameterHandler &prm);
  };

  /// The registry of force models.
  using ForceModelRegistry = PluginRegistry<ForceModel>;
} // namespace lacerta::physics

/// Registers a force model plugin.
#define LACERTA_REGISTER_FORCE_MODEL(classname, name, description) \
  LACERTA_REGISTER_PLUGIN(lacerta::physics::ForceModel, classname, name, description)
