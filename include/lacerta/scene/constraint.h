/**
 * @file
 * Constraints on regions of the object: fixed, moved along a path, or pulled by a force
 * (plugins, `subsection Constraints`).
 */
#pragma once

#include <lacerta/base/plugins.h>
#include <lacerta/mesh/tet_mesh.h>

#include <array>
#include <memory>
#include <string>
#include <utility>
#include <vector>

namespace lacerta::physics
{
  class ParticleSystem;
}

namespace lacerta
{
  class Archive;
}
namespace lacerta::scene
{
  class Region;

  /**
   * A constraint acts on the particles of a region: it prescribes their motion (they
   * are then not free) or applies forces to them.
   *
   * A scene names its constraints in `subsection Constraints`, `set Names = a, b`; each
   * has a subsection of that name with `Type` (the plugin), `Region` (a region plugin)
   * and the plugins' own subsections.
   */
  class Constraint
  {
  public:
    /// Kind name used in messages and in the documentation.
    static std::string
    plugin_kind()
    {
      return "constraint";
    }

    virtual ~Constraint() = default;

    /// Reads the plugin's parameters from its subsection.
    virtual void
    parse_parameters(dealii::ParameterHandler &prm) = 0;

    /**
     * Takes the particles it acts on; constraints that prescribe motion mark them as
     * not free in @p system.
     */
    virtual void
    initialize(const std::vector<unsigned int> &particles,
               physics::ParticleSystem         &system);

    /**
     * Extends the constraint to the particles a cut copied from its own (@p copies:
     * (original, copy) in the order made, so copies of copies follow) and initialises
     * it again, since the cut changed the masses: a fixed particle's copy stays fixed,
     * a handle keeps pulling all of its tissue.
     */
    void
    follow_copies(const std::vector<std::array<unsigned int, 2>> &copies,
                  physics::ParticleSystem                        &system);

    /**
     * Follows renumbered particles (@p new_index: the new index of every particle,
     * TopologyUpdate::particle_renumbering(); nothing if empty) and initialises the
     * constraint again (a new level of detail changed the masses). Its particles are
     * never among the removed ones: the MT never removes a constrained vertex.
     */
    void
    follow_renumbering(const std::vector<unsigned int> &new_index,
                       physics::ParticleSystem         &system);

    /// Whether the constraint prescribes the motion of its particles.
    virtual bool
    prescribes_motion() const = 0;

    /**
     * Readies the motion prescribed at time @p t for prescribe() (what the motion's
     * expression gives, evaluated once per time level), given the rest positions
     * @p rest. Nothing by default.
     */
    virtual void
    prepare(double t, const double *rest);

    /**
     * Writes the positions and velocities prepare() readied into @p x and @p v (3
     * values per particle) for the constraint's particles in [@p begin, @p end),
     * given the rest positions @p rest, and no other entry: the threads' ranges of
     * particles call it in parallel. Nothing by default.
     */
    virtual void
    prescribe(const double *rest,
              double       *x,
              double       *v,
              unsigned int  begin,
              unsigned int  end) const;

    /// Adds the forces the constraint applies at time @p t to the system's external
    /// forces.
    virtual void
    add_forces(double t, physics::ParticleSystem &system) const;

    /**
     * Writes or reads what the constraint has learnt during the run, for a checkpoint
     * (see lacerta::Archive): its particles (cuts add copies) and what it derived from
     * them.
     */
    virtual void
    serialize(Archive &archive);

    /// The instance's name in the parameter file.
    std::string name;
    /// The particles the constraint acts on, in increasing order (initialize() sorts
    /// them).
    std::vector<unsigned int> particles;

    /// The region that selects them (again on every level of detail).
    std::shared_ptr<const Region> region;

    /**
     * Declares `subsection Constraints` with `Names` and, for every name, its
     * subsection with `Type`, `Region` and the subsections of all constraint and
     * region plugins.
     */
    static void
    declare_parameters(dealii::ParameterHandler       &prm,
                       const std::vector<std::string> &names);

    /// The instance names listed in `Constraints/Names`.
    static std::vector<std::string>
    names(dealii::ParameterHandler &prm);

    /**
     * Creates every named constraint with its region's particles in @p mesh. A region
     * that selects no particle is an Error naming the constraint.
     */
    static std::vector<std::unique_ptr<Constraint>>
    create(dealii::ParameterHandler &prm, const mesh::TetMesh &mesh);

  protected:
    /**
     * The positions in #particles of the constraint's particles in [@p begin,
     * @p end): the half-open range of indices into #particles that prescribe() writes.
     */
    std::pair<std::size_t, std::size_t>
    particles_in(unsigned int begin, unsigned int end) const;
  };

  /// The registry of constraints.
  using ConstraintRegistry = PluginRegistry<Constraint>;
} // namespace lacerta::scene

/// Registers a constraint plugin.
#define LACERTA_REGISTER_CONSTRAINT(classname, name, description) \
  LACERTA_REGISTER_PLUGIN(lacerta::scene::Constraint, classname, name, description)
