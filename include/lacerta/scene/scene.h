/**
 * @file
 * A scene: the object (mesh, material), its particle system, constraints and loads.
 */
#pragma once

#include <lacerta/base/signal.h>
#include <lacerta/cut/cutter.h>
#include <lacerta/mesh/tet_mesh.h>
#include <lacerta/mt/mt_cutter.h>
#include <lacerta/scene/body_force.h>
#include <lacerta/scene/constraint.h>
#include <lacerta/scene/material.h>
#include <lacerta/scene/system_change.h>

#include <array>
#include <memory>
#include <optional>
#include <ostream>
#include <vector>

namespace lacerta::physics
{
  class ParticleSystem;
  class TopologyUpdate;
} // namespace lacerta::physics
namespace lacerta::mt
{
  class Multiresolution;
}

namespace lacerta::cut
{
  class Tool;
  class Lacerator;
  struct LacerationStatistics;
} // namespace lacerta::cut

namespace lacerta
{
  class Archive;
}
namespace lacerta::scene
{
  /// What Scene::update_multiresolution_after_cut() did.
  struct MultiresolutionCut
  {
    /// The MT update (SF, MT tetrahedra cut and created, MT-DAGUpd).
    mt::MtCutter::Statistics update;
    /// The level of detail, which is the cutter's mesh: tetrahedra, particles, pieces.
    unsigned int n_tets = 0, n_particles = 0, pieces = 0;
    /// Simulated time of the update (s).
    double time = 0;
  };


  /**
   * Builds and owns what a parameter file describes: the mesh (numbered spatially), the
   * material, the particle system with its masses (3.1) and springs (3.2), the
   * constraints and the body forces.
   */
  class Scene
  {
  public:
    /**
     * Declares the scene's subsections (Mesh, Material, Force model, Body forces,
     * Constraints with the given instance names).
     */
    static void
    declare_parameters(dealii::ParameterHandler       &prm,
                       const std::vector<std::string> &constraint_names);

    /**
     * Builds everything from @p prm; the force evaluation runs on @p n_threads threads.
     * Bad input is a lacerta::Error naming the entry, file, element or particle.
     */
    Scene(dealii::ParameterHandler &prm, unsigned int n_threads);

    /// A scene is neither copied nor moved: its subscribers hold its address.
    Scene(const Scene &) = delete;
    Scene &
    operator=(const Scene &) = delete;

    ~Scene();

    /**
     * Emitted after every change of the particle system (a cut, a tear, a new level of
     * detail), once the scene has followed it itself:
     * the constraints take over the copies of their particles, the cutter restarts on
     * a new mesh, the lacerator learns what changed. Subscribers (the simulator's
     * integrator and stability control, a viewer) connect to it; the scene's own
     * reaction is connected first.
     */
    Signal<const SystemChange &> system_changed;

    /**
     * Emitted after the MT was updated with a stroke's or a tear's records
     * (update_multiresolution_after_cut()). The particle system does not change.
     */
    Signal<const MultiresolutionCut &> multi_triangulation_cut;

    /**
     * Moves the scalpel's blade to @p blade (cut::Cutter::move_blade()) on the state at
     * time @p t and cuts what it sweeps; if the mesh changed, emits system_changed.
     * Requires a tool.
     */
    cut::CutStepStatistics
    cut(const cut::Blade &blade, double t);

    /**
     * Lets the lacerator tear the springs past their limit on the state at time @p t
     * (cut::Lacerator::check()); if it tore, emits system_changed. Requires
     * lacerations.
     */
    cut::LacerationStatistics
    lacerate(double t);

    /**
     * With multiresolution: re-extracts the level of detail if the focus at time @p t
     * (step @p step; with `Focus follows = tool` the cutter's blade) asks for it and, if
     * it changed, rebuilds the particle system on it with the particles' state carried
     * over (Section 4.2), writing a line to @p out, and emits system_changed.
     * Postponed while a cut waits for its MT update (update_multiresolution_after_cut()).
     * Returns whether the particle system changed; without multiresolution, false.
     */
    bool
    update_level_of_detail(double t, unsigned int step, std::ostream &out);

    /**
     * With multiresolution: once the scalpel's stroke is over (its blade is in no
     * tetrahedron, or there is no scalpel) and the scalpel or a tear has cut the level
     * of detail since the last call, replays their records on the MT (the level of
     * detail stays the cut mesh; later extractions keep the cut) and emits
     * multi_triangulation_cut at time @p t. Returns what it did, or nothing if there was
     * nothing to do.
     */
    std::optional<MultiresolutionCut>
    update_multiresolution_after_cut(double t);

    /// Whether a cut on the multiresolution model waits for its MT update.
    bool
    cut_pending() const
    {
      return !cut_records.empty();
    }

    /**
     * The volume the active mesh must have: the mesh's as built, or with
     * multiresolution the level of detail's when it was extracted (cuts conserve it).
     */
    double
    expected_volume() const
    {
      return multiresolution ? level_of_detail_volume : initial_volume;
    }

    /// The mesh the particle system lives on: the level of detail, or the mesh.
    const mesh::TetMesh &
    active_mesh() const;

    /// Recomputes the external forces at time @p t (only if some load varies).
    void
    update_loads(double t);

    /**
     * Writes or reads the scene's state for a checkpoint (see lacerta::Archive): the
     * mesh with its cuts, the multiresolution model, the particle system, the
     * constraints, the cutter and the lacerator. A scene built from the same parameters
     * then goes on exactly as the one that wrote it.
     */
    void
    serialize(Archive &archive);

    /// Writes a description of the scene (sizes, mass, stiffness range, constraints).
    void
    print_summary(std::ostream &out) const;

    /// The mesh in its rest configuration.
    mesh::TetMesh mesh;
    /// The material fields.
    Material material;
    /// The particle system.
    std::unique_ptr<physics::ParticleSystem> system;
    /// The constraints, in the order of `Constraints/Names`.
    std::vector<std::unique_ptr<Constraint>> constraints;
    /// The body forces.
    std::vector<std::unique_ptr<BodyForce>> body_forces;
    /// ∫σ over the mesh, with the rule of the mass assembly (kept up to date by cuts).
    double integral_of_density = 0;
    /// The multiresolution model, only if the scene enables it.
    std::unique_ptr<mt::Multiresolution> multiresolution;

    /// The stability of a system at rest (physics/stability.h).
    struct StabilityAtRest
    {
      /// Bound on the highest angular eigenfrequency (rad/s).
      double omega = 0;
      /// physics::multirate_evaluation_share().
      double multirate_share = 1;
    };
    /// With multiresolution: the full mesh's, assembled at rest once at the start.
    StabilityAtRest full_mesh_stability;
    /// Volume of the mesh as built (cuts conserve it).
    double initial_volume = 0;
    /// The cutting tool and the cutter, only if `Tool/Type` is not `none`.
    std::unique_ptr<cut::Tool>   tool;
    std::unique_ptr<cut::Cutter> cutter;

    /// The lacerator, only if `Laceration/Enabled` is true.
    std::unique_ptr<cut::Lacerator> lacerator;

  private:
    /**
     * The scene's own reaction to @p change, connected to system_changed first: after
     * a cut or a tear the constraints take over the copies of their particles and
     * follow the new masses; the lacerator learns of a cut; after a tear or a
     * reassembly the cutter restarts, and after a reassembly the lacerator learns
     * which particles the MT's cuts created.
     */
    void
    follow_change(const SystemChange &change);

    /**
     * The cutter starts afresh on the mesh to cut at its blade (a stroke in progress
     * restarts there), so that its search structures see what a tear or a new level
     * of detail changed. Nothing without a cutter.
     */
    void
    restart_cutter();

    /**
     * Sets the particle system up on @p active (the mesh or a level of detail) at time
     * @p t: masses (scaled to ∫σ over the mesh), springs, damping, body forces,
     * constraints (their regions select the particles of @p active) and loads.
     */
    void
    assemble(const mesh::TetMesh &active, double t);

    /**
     * Moves the particle system to the level of detail the last extraction chose, at
     * time @p t, locally (Multiresolution::apply_change() through `level_update`, the
     * update a cut makes): the mass of the swapped region is kept, the constraints
     * follow the renumbered particles and are enforced. Returns the particles' new
     * indices (SystemChange::particle_renumbering).
     */
    const std::vector<unsigned int> &
    move_to_level_of_detail(double t);

    /// The mesh the cutter cuts: the level of detail's, or the mesh.
    mesh::TetMesh &
    mesh_to_cut();

    /// The records of the sweeps of the cutter and the lacerator's cutters since the
    /// last MT update (multiresolution).
    std::vector<cut::CutRecord> cut_records;
    /// Volume of the level of detail: when it was assembled, then followed through
    /// every change of level.
    double level_of_detail_volume = 0;
    /// The factor the level of detail's lumped masses were scaled by when it was
    /// assembled, so that they sum to ∫σ; later changes of level use it too.
    double level_mass_scale = 1;
    /// The local update of the level of detail's mesh and particle system (made at
    /// the first change of level).
    std::unique_ptr<physics::TopologyUpdate> level_update;
    /// The parameters of `subsection Cut`, for restart_cutter().
    cut::Cutter::Parameters cutter_parameters;
    bool                    has_varying_loads = false;
    unsigned int            n_threads         = 1;
  };
} // namespace lacerta::scene
