/**
 * @file
 * What one blade motion did, and the boundary id of the faces a cut opens.
 */
#pragma once

#include <array>
#include <vector>

namespace lacerta::cut
{
  /// Boundary id of the faces a cut opens (the two sheets of the crack).
  inline constexpr unsigned int cut_boundary_id = 99;

  /**
   * What one blade motion did: the columns of the paper's Table 1 and a little more.
   */
  struct CutStepStatistics
  {
    /// Tetrahedra replaced (CuT) and tetrahedra created (CrT).
    unsigned int cut_tets = 0, created_tets = 0;
    /// Particles created (cut points, copies of points on the cut).
    unsigned int new_particles = 0;
    /// Sub-steps of the swept surface.
    unsigned int sweeps = 0;
    /// Wall time of the local mesh and physics update, and of the force model's
    /// update for the springs the motion changed (ForceModel::springs_changed()), in
    /// seconds.
    double update_seconds = 0, reinit_seconds = 0;
    /**
     * Where the time went, in seconds. `search_seconds` (not part of update_seconds):
     * the boundary face tree's refit, the first contact and the propagation
     * (FindTetraToCut). The parts of update_seconds: `analysis_seconds` (the crossings
     * decided, the cells cut through and the closure around them, one TetCut per cell),
     * `split_seconds` (the split table),
     * `children_seconds` (the children's nodes, new particles, copies of the points
     * on the cut), `mesh_seconds` (TetMesh::replace_tets()) and `physics_seconds`
     * (masses, springs, the tree's new faces, the active set).
     */
    double search_seconds = 0, analysis_seconds = 0, split_seconds = 0,
           children_seconds = 0, mesh_seconds = 0, physics_seconds = 0;
    /// Whether the mesh changed (then the integrator must be re-initialised).
    bool changed = false;
    /**
     * Particles duplicated along the cut surface, as (original, copy), in the order
     * made (a copy can be copied again later). A copy starts with its original's
     * state and `free` flag; whoever holds particle lists (the scene's constraints)
     * extends them so that a fixed particle stays fixed and a handle keeps pulling.
     */
    std::vector<std::array<unsigned int, 2>> copied_particles;
  };
} // namespace lacerta::cut
