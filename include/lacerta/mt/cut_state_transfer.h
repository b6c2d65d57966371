/**
 * @file
 * Carrying the particles' state from the mesh the Cutter cut to the Multi-Triangulation's
 * version of the same cut level of detail (doc/mt-cutting.md), whose cut vertices are
 * not the cutter's particles vertex for vertex.
 */
#pragma once

#include <lacerta/mesh/tet_mesh.h>

#include <vector>

namespace lacerta::mt
{
  /// How transfer_state_across_cut() found the state of the new vertices.
  struct CutTransferReport
  {
    /// Vertices with a particle of the old mesh at the same rest position on the same
    /// side of the cut (state copied) and vertices interpolated.
    unsigned int copied = 0, interpolated = 0;
  };

  /**
   * Fills positions @p x and velocities @p v (3 per vertex of @p to) from the state
   * @p from_x, @p from_v of the particles of @p from. Both meshes are in the rest
   * configuration and cover the same cut object. A vertex of @p to at the rest position
   * of particles of @p from takes the state of the one whose tetrahedra lie on its
   * side (copies on a cut share a position); any other vertex is interpolated in the
   * tetrahedron of @p from that contains a point a quarter of the way into one of its
   * own tetrahedra (which do not cross the cut, so the side is unambiguous), with its
   * barycentric coordinates there (clamped to a small extrapolation).
   */
  CutTransferReport
  transfer_state_across_cut(const mesh::TetMesh       &from,
                            const std::vector<double> &from_x,
                            const std::vector<double> &from_v,
                            const mesh::TetMesh       &to,
                            std::vector<double>       &x,
                            std::vector<double>       &v);
} // namespace lacerta::mt
