/**
 * @file
 * The particle system (Section 3): state, masses, springs, loads and constraints.
 */
#pragma once

#include <lacerta/physics/range_update.h>
#include <lacerta/physics/spring_set.h>

#include <array>
#include <functional>
#include <memory>
#include <vector>

namespace dealii
{
  template <int dim, typename Number>
  class Function;
}

namespace lacerta
{
  class Archive;
}
namespace lacerta::mesh
{
  class TetMesh;
}

namespace lacerta::physics
{
  class ForceModel;

  /**
   * Everything the integrators advance: positions and velocities (3 doubles per
   * particle, interleaved), masses, springs, damping, loads and which particles move
   * freely. Particles are indexed by mesh vertex id.
   *
   * The equations of motion are M x'' = f_springs(x, x') + M g + f_ext - c M x' for the
   * free particles; the constrained ones follow the motion the scene prescribes.
   */
  class ParticleSystem
  {
  public:
    /// Positions, 3 per particle.
    std::vector<double> position;
    /// Velocities, 3 per particle.
    std::vector<double> velocity;
    /// Lumped masses (kg).
    std::vector<double> mass;
    /**
     * The part of each mass that physics::MassBalancer moved there from other
     * particles (kg; sums to zero): `mass - mass_shift` is the lumped ∫σ c_i that the
     * assembly and the local updates of cuts add and subtract.
     */
    std::vector<double> mass_shift;
    /// 1 for a free particle, 0 for one whose motion is prescribed.
    std::vector<double> free;
    /// External forces (N), 3 per particle; set by the scene's force handles.
    std::vector<double> external_force;
    /// The springs (Section 3.2).
    SpringSet springs;
    /// Uniform body acceleration, e.g. gravity (m/s²).
    std::array<double, 3> body_acceleration = {{0, 0, 0}};
    /// Viscous damping per particle, force -c m v (1/s).
    double mass_damping = 0;
    /// Damping along springs, force -β k ((v_b - v_a)·n) n (s).
    double spring_damping = 0;

    /**
     * The tetrahedra of the particles (particle i is vertex i; the rest shapes are the
     * mesh's vertices), for the force models per tetrahedron; set by whoever assembles
     * the system, and changed in place by cuts before springs_changed(). May be null
     * for the paper's springs.
     */
    const mesh::TetMesh *mesh = nullptr;
    /// Young's modulus E(x) (Pa) of the force models per tetrahedron, evaluated at
    /// centroids at rest, as for the springs; may be null for the paper's springs.
    const dealii::Function<3, double> *youngs_modulus = nullptr;
    /// The Poisson ratio the force models per tetrahedron reproduce.
    double poisson_ratio = 0.25;
    /// Whether the springs were fitted per tetrahedron with `poisson_ratio`
    /// (compute_fitted_springs()) rather than made by Section 3.2's rule: the local
    /// updates of cuts, tears and levels of detail (TopologyUpdate) follow the same rule.
    bool fitted_springs = false;
    /**
     * Per cell of `mesh`: its contributions to its six edges' stiffnesses (local edge
     * order), when they do not come from a rule applied to the cell's own shape (the
     * condensed stiffness of a level of detail, doc/multiresolution.md); empty when
     * they do. TopologyUpdate keeps it along the cells.
     */
    std::vector<std::array<double, 6>> cell_stiffness;

    /**
     * How the scene prescribes the constrained particles' motion, in two parts:
     * `prepare_constraints(t)` readies the motion at time t, then
     * `prescribe_constraints(x, v, begin, end)` writes it into the positions x and
     * velocities v of the constrained particles in [begin, end), and no other entry,
     * so that every thread's range of particles can do it in parallel (an
     * integrator's RangeUpdate). Both do nothing unless the scene sets them.
     */
    std::function<void(double)> prepare_constraints = [](double) {};
    /// See prepare_constraints.
    std::function<void(double *, double *, unsigned int, unsigned int)>
      prescribe_constraints = [](double *, double *, unsigned int, unsigned int) {};

    /**
     * Wall time spent in compute_acceleration() since it was last reset (s). It
     * includes what runs in the force evaluation's parallel pass: the integrator's
     * update of each range (RangeUpdate) and the constraints' prescription.
     */
    mutable double force_seconds = 0;

    /// Creates @p n_particles particles at rest at @p rest_positions (3 per particle).
    ParticleSystem(const std::vector<double> &rest_positions);

    ~ParticleSystem();

    /// Number of particles.
    unsigned int
    n_particles() const
    {
      return static_cast<unsigned int>(mass.size());
    }

    /// The current position of particle @p i.
    std::array<double, 3>
    current_position(const unsigned int i) const
    {
      return {{position[3 * i], position[3 * i + 1], position[3 * i + 2]}};
    }

    /**
     * Makes room for @p n particles, so that add_particle() up to that many copies
     * no array (the cutter adds particles in its local updates).
     */
    void
    reserve(unsigned int n);

    /// Sets the force model; it is initialised for the current springs.
    void
    set_force_model(std::unique_ptr<ForceModel> model, unsigned int n_threads);

    /**
     * Replaces every particle by @p rest_positions.size() / 3 free particles at rest
     * there, without springs, masses or body acceleration (a level of detail change);
     * the caller fills them and then calls update_force_model().
     */
    void
    reset(const std::vector<double> &rest_positions);

    /// Prepares the force model again for the current springs on @p n_threads threads.
    void
    update_force_model(unsigned int n_threads);

    /**
     * Re-initialises the force model for all springs, on the thread count it was set
     * with.
     */
    void
    refresh_force_model();

    /**
     * Tells the force model that the springs listed in @p changed_springs (and the slots
     * removed from the end of `springs`, and new particles) changed locally: a cut or
     * a tear (ForceModel::springs_changed()).
     */
    void
    springs_changed(const std::vector<unsigned int> &changed_springs);

    /**
     * Tells the force model that the masses of @p particles changed (and nothing else).
     */
    void
    masses_changed(const std::vector<unsigned int> &particles);

    /**
     * Appends a free particle with rest position @p rest, position @p x, velocity
     * @p v and zero mass (the cutter sets the masses); returns its index.
     */
    unsigned int
    add_particle(const std::array<double, 3> &rest,
                 const std::array<double, 3> &x,
                 const std::array<double, 3> &v);

    /**
     * Removes @p n_removed particles the way TetMesh::remove_vertices() removed their
     * vertices: every pair (to, from) of @p moves, in order, copies particle `from`
     * into slot `to`, then the last @p n_removed slots go. The springs are the
     * caller's (they follow the mesh's edges). The moved particles count as changed
     * (changed_particles()); the removed ones leave that list.
     */
    void
    remove_particles(const std::vector<std::array<unsigned int, 2>> &moves,
                     unsigned int                                    n_removed);

    /**
     * Gives every particle i the index @p new_index[i] (a permutation, as
     * TetMesh::renumber_vertices() gave their vertices): its state, rest position,
     * mass and constraint flag move with it. The springs are the caller's (they follow
     * the mesh's edges). Every particle counts as changed (all_particles_changed()).
     */
    void
    renumber_particles(const std::vector<unsigned int> &new_index);

    /**
     * The particles whose springs, mass or existence changed locally since
     * clear_changes(), each once, in the order first reported: the ends of the springs
     * passed to springs_changed() (the particles whose tetrahedra changed are among
     * them or their neighbours), those passed to masses_changed(), and those appended
     * by add_particle(). What the stability bound and the blow-up monitor update after
     * a cut or a tear. Empty when all_particles_changed().
     */
    const std::vector<unsigned int> &
    changed_particles() const
    {
      return changed;
    }

    /// Whether every particle counts as changed since clear_changes(): after reset()
    /// (a new level of detail).
    bool
    all_particles_changed() const
    {
      return all_changed;
    }

    /// Empties changed_particles() and ends all_particles_changed() (whoever reacted
    /// to the changes calls it).
    void
    clear_changes();

    /// Whether a force model was set (set_force_model()).
    bool
    has_force_model() const
    {
      return forces != nullptr;
    }

    /// The force model.
    const ForceModel &
    force_model() const
    {
      return *forces;
    }

    /**
     * Accelerations a(x, v) at state (x, v): spring forces, damping, loads, divided by
     * the masses; zero for constrained particles. No allocation.
     */
    void
    compute_acceleration(const double *x, const double *v, double *a) const;

    /**
     * Accelerations, as above, and @p update of every thread range's particles in the
     * same parallel pass (see RangeUpdate).
     */
    void
    compute_acceleration(const double *x,
                         const double *v,
                         double       *a,
                         RangeUpdate   update) const;

    /**
     * Puts every constrained particle where the scene prescribes it at time @p t, in
     * the positions @p x and velocities @p v (prepare_constraints, then
     * prescribe_constraints over all particles).
     */
    void
    enforce_constraints(double t, double *x, double *v) const;

    /// Kinetic energy ½ Σ m |v|² of the current state.
    double
    kinetic_energy() const;

    /// Potential energy of the body force, -Σ m g·(x - x_rest) (J).
    double
    body_force_energy() const;

    /// Elastic energy of the springs at the current positions.
    double
    elastic_energy() const;

    /// Writes or reads the state for a checkpoint (see lacerta::Archive).
    void
    serialize(Archive &archive);

    /// Rest positions the system was created with.
    const std::vector<double> &
    rest_position() const
    {
      return rest;
    }

  private:
    /// Calls @p f(array, values per particle) for every array by particle: the state,
    /// loads, rest positions, masses and constraint flags.
    template <typename Function>
    void
    for_each_particle_array(const Function &f);

    std::vector<double>         rest;
    std::unique_ptr<ForceModel> forces;
    unsigned int                force_threads = 1;
    /// See changed_particles() and all_particles_changed(); `listed` marks the
    /// particles in `changed`.
    std::vector<unsigned int>  changed;
    std::vector<unsigned char> listed;
    bool                       all_changed = false;

    /// Lists particle @p i in changed_particles(), unless all count as changed.
    void
    note_changed(unsigned int i);
  };
} // namespace lacerta::physics
