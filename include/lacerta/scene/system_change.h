/**
 * @file
 * The event "the particle system changed": what a cut, a tear or a new level of
 * detail tells the rest of the program.
 */
#pragma once

#include <array>
#include <string>
#include <vector>

namespace lacerta::cut
{
  struct CutStepStatistics;
  struct LacerationStatistics;
} // namespace lacerta::cut

namespace lacerta::scene
{
  /**
   * A change of the particle system's topology: its particles, springs or masses are
   * others than before. Scene::system_changed carries it to every subscriber.
   */
  struct SystemChange
  {
    /// What changed the system.
    enum class Cause
    {
      /// The scalpel cut the mesh locally.
      cut,
      /// A tear cut the mesh locally.
      laceration,
      /// The system moved locally to a newly extracted level of detail.
      level_of_detail
    };

    Cause cause;
    /// Simulated time of the changed state (s).
    double time = 0;
    /**
     * What the change did: the blade motion's statistics for a cut, the tear's for a
     * laceration; nullptr otherwise. Valid during the event only.
     */
    const cut::CutStepStatistics    *cut  = nullptr;
    const cut::LacerationStatistics *tear = nullptr;

    /// Particles a local cut or tear duplicated along its surface, as (original, copy)
    /// (cut::CutStepStatistics::copied_particles); empty after a reassembly.
    const std::vector<std::array<unsigned int, 2>> &
    copied_particles() const;

    /**
     * A change of the level of detail removes particles and may renumber all of them:
     * the new index of every particle, or mesh::invalid_index for a removed one
     * (TopologyUpdate::particle_renumbering(); the identity where nothing moved).
     * Subscribers that keep particle ids follow it; nullptr for a cut or a tear, which
     * only add particles.
     */
    const std::vector<unsigned int> *particle_renumbering = nullptr;

    /// The cause in words, for messages: "the cut", "the laceration", ...
    std::string
    describe() const;
  };
} // namespace lacerta::scene
