/**
 * @file
 * The stiffness of a coarse level of detail condensed from the fine mesh it stands
 * for (issue 17, item 2; doc/multiresolution.md).
 */
#pragma once

#include <lacerta/mesh/point.h>
#include <lacerta/mt/multi_triangulation.h>

#include <array>
#include <functional>
#include <vector>

namespace lacerta::mt
{
  /// The contributions of a tetrahedron with the given rest vertices to the stiffness
  /// of its six edges (local order mesh::TetMesh::edge_vertices), by a spring rule.
  using EdgeStiffnessRule =
    std::function<std::array<double, 6>(const std::array<mesh::Point3, 4> &)>;

  /**
   * Per tetrahedron of @p mt, the contributions to the stiffness of its six edges (in
   * the order of mesh::TetMesh::edge_vertices on its vertices as the MT stores them)
   * condensed from the input mesh.
   *
   * The tetrahedra of the input mesh get @p rule. The coarse fragment of every node
   * (the tetrahedra a half-edge collapse made) gets its rule's springs, scaled per edge
   * so that their energies under the six uniform strains are nearest to those of the
   * fine fragment it replaced with the removed vertex condensed out (the Schur
   * complement K_cc - K_cp K_pp⁻¹ K_pc of the fine fragment's linearised springs: the
   * stiffness the fine fragment opposes to the coarse vertices when the removed vertex
   * settles where its springs hold it), with a small pull of every scale towards one
   * scale for the whole fragment and a floor of 0.05 of it. Collapses are replayed in
   * the order of the decimation, so that a fine fragment that is itself coarse carries
   * the condensed stiffness of everything below it.
   */
  std::vector<std::array<double, 6>>
  condensed_edge_stiffnesses(const MultiTriangulation &mt, const EdgeStiffnessRule &rule);
} // namespace lacerta::mt
