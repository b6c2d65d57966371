/**
 * @file
 * The invariants a cut must keep (ARCHITECTURE.md, "Exact bookkeeping"), checked by the
 * tests after every step and at run time with `set Check invariants = true`.
 */
#pragma once

#include <lacerta/mesh/tet_mesh.h>

#include <string>
#include <vector>

namespace lacerta::physics
{
  class ParticleSystem;
}

namespace lacerta::cut
{
  /**
   * Checks @p mesh and @p system: the volume equals @p volume (relative 1e-9); every
   * tetrahedron is positively oriented and not near-flat (volume above 1e-9 times the
   * cube of its longest edge); the mesh conforms (every neighbour link is mutual and
   * across the same three vertices, every face without neighbour is a boundary face,
   * the boundary closes up); the springs are the edges; every particle has positive
   * mass; the total mass equals @p integral_of_density (relative 1e-9). Returns an empty
   * string, or a description of the first violation. O(mesh size).
   */
  std::string
  check_invariants(const mesh::TetMesh           &mesh,
                   const physics::ParticleSystem &system,
                   double                         volume,
                   double                         integral_of_density);

  /// Volumes of the connected components of @p mesh (through shared faces), sorted.
  std::vector<double>
  component_volumes(const mesh::TetMesh &mesh);

  /// Number of connected components of @p mesh through shared faces.
  unsigned int
  count_components(const mesh::TetMesh &mesh);
} // namespace lacerta::cut
