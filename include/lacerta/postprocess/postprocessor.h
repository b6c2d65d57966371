/**
 * @file
 * Postprocessors: what a run writes (plugins, `subsection Postprocess`).
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
namespace lacerta::mesh
{
  class TetMesh;
}
namespace lacerta::physics
{
  class ParticleSystem;
}
namespace lacerta::scene
{
  class Material;
  class Scene;
} // namespace lacerta::scene
namespace lacerta::cut
{
  struct Blade;
}

namespace lacerta::postprocess
{
  /**
   * What a postprocessor sees after a step.
   */
  struct RunState
  {
    const mesh::TetMesh           *mesh     = nullptr;
    const physics::ParticleSystem *system   = nullptr;
    const scene::Material         *material = nullptr;
    /// Where the scalpel's blade is, or nullptr in a scene without a tool.
    const cut::Blade *blade = nullptr;
    /// Step number (0 before the first step).
    unsigned int step = 0;
    /// Simulated time (s).
    double time = 0;
    /// Time step of this step and the number of sub-steps it was split into.
    double       time_step = 0;
    unsigned int substeps  = 1;
    /// Energies (J) and the work done by the loads since the start (J).
    double kinetic_energy = 0, elastic_energy = 0, body_force_energy = 0, input_work = 0;
    /// Wall time of this step's force evaluations (with the integrator's update and the
    /// constraints done in the same parallel pass) and of the whole step (s).
    double force_seconds = 0, step_seconds = 0;
    /// Cuts of this step (the paper's Table 1): tetrahedra cut and created, and the
    /// wall time of the mesh update (s); all zero in a scene without a tool.
    unsigned int cut_tets = 0, created_tets = 0;
    double       update_seconds = 0;
    /// Wall time of the whole blade motion: first contact and propagation, the mesh
    /// and physics update and the force model's update (s).
    double cut_step_seconds = 0;
    /// Lacerations of this step (Section 7): surface springs past their limit, tears,
    /// tetrahedra the tear split and created, and its wall time (s); all zero in a
    /// scene without lacerations.
    unsigned int over_limit = 0, tears = 0, torn_tets = 0, tear_created_tets = 0;
    double       tear_seconds = 0;
    /// The MT update after a stroke on a multiresolution model (the paper's Table 2):
    /// fragments split (SF) and its wall time (MT-DAGUpd, s); zero at other steps.
    unsigned int split_fragments   = 0;
    double       mt_update_seconds = 0;
    /// Wall time of this step's integration (s).
    double integration_seconds = 0;
    /// Whether the level of detail was re-extracted at the end of this step, and the
    /// wall time of it (s; the move of the particle system included).
    bool   reextracted          = false;
    double reextraction_seconds = 0;
  };


  /**
   * A postprocessor writes something about the run after every step (or every few).
   */
  class Postprocessor
  {
  public:
    /// Kind name used in messages and in the documentation.
    static std::string
    plugin_kind()
    {
      return "postprocessor";
    }

    virtual ~Postprocessor() = default;

    /// Reads the plugin's parameters from its subsection (by default, none).
    virtual void
    parse_parameters(dealii::ParameterHandler &prm);

    /**
     * Prepares output into @p output_directory; in @p test_mode nothing that depends
     * on the machine (wall times) is written.
     */
    virtual void
    initialize(const std::string &output_directory, bool test_mode) = 0;

    /**
     * Connects to the events of @p scene (Scene::system_changed) if the postprocessor
     * reports them as they happen; by default it does not. Called once, after
     * initialize() and before the simulator's own subscriber, so that what it prints
     * of a change comes before any error the change causes.
     */
    virtual void
    subscribe(scene::Scene &scene);

    /// Whether execute() at time @p time needs the energies of the state.
    virtual bool
    needs_energies(double time) const;

    /// Whether execute() at time @p time writes the state (it is checked for blow-up
    /// first).
    virtual bool
    writes_state(double time) const;

    /// Called after every step (and once before the first, with step 0).
    virtual void
    execute(const RunState &state) = 0;

    /// Called once when the run ends, with the last state (summaries).
    virtual void
    finish(const RunState &state);

    /**
     * Writes or reads what the postprocessor has gathered or written so far, for a
     * checkpoint (see lacerta::Archive): after a resume it goes on as if the run had
     * not stopped. An Error if it cannot be resumed.
     */
    virtual void
    serialize(Archive &archive) = 0;

    /// Declares `subsection Postprocess` with the list and every plugin's subsection.
    static void
    declare_parameters(dealii::ParameterHandler &prm);

    /**
     * Creates the postprocessors listed in `subsection Postprocess`, preceded by those
     * of @p required the list does not name (what the scene needs whatever the list
     * says).
     */
    static std::vector<std::unique_ptr<Postprocessor>>
    create(dealii::ParameterHandler &prm, const std::vector<std::string> &required = {});
  };

  /// The registry of postprocessors.
  using PostprocessorRegistry = PluginRegistry<Postprocessor>;
} // namespace lacerta::postprocess

/// Registers a postprocessor plugin.
#define LACERTA_REGISTER_POSTPROCESSOR(classname, name, description) \
  LACERTA_REGISTER_PLUGIN(lacerta::postprocess::Postprocessor,       \
                          classname,                                 \
                          name,                                      \
                          description)
