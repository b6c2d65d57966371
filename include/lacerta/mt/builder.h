/**
 * @file
 * Building a Multi-Triangulation by decimation (Section 4.1).
 */
#pragma once

#include <lacerta/mesh/tet_mesh.h>
#include <lacerta/mt/multi_triangulation.h>

#include <vector>

namespace lacerta::mt
{
  /**
   * What the decimation may do.
   */
  struct BuilderParameters
  {
    /**
     * No collapse may create a tetrahedron whose mean-ratio quality
     * 12 (3V)^(2/3) / Σ l² (1 for the regular tetrahedron, 0 for a flat one) is below
     * this; inverted tetrahedra have negative volume and are always rejected. Springs
     * on flat tetrahedra are a softer material than the fine cells they replace
     * (doc/multiresolution.md, "The material of a level of detail").
     */
    double minimum_quality = 0.3;
    /**
     * Largest approximate Hausdorff distance between the decimated boundary and the
     * input boundary, as a fraction of the diagonal of the bounding box.
     */
    double maximum_boundary_error = 0.01;
    /**
     * Weight of the boundary distance in the priority of a boundary vertex:
     * V̄ (1 + weight d / l̄), with V̄ the mean volume of the incident tetrahedra, d the
     * Hausdorff distance its removal causes and l̄ the mean length of its edges.
     */
    double boundary_error_weight = 10;
  };

  /**
   * Decimates @p mesh by half-edge collapses and returns the Multi-Triangulation of
   * the whole process.
   *
   * A vertex v is removed by collapsing it onto a neighbour w: the tetrahedra around
   * edge vw disappear and the others around v get w in place of v, which
   * retriangulates v's star. A collapse is rejected if a new tetrahedron is inverted or
   * below the minimum quality, if it breaks the link condition (with a ghost vertex
   * closing the boundary, so that the boundary's topology cannot change either), if a
   * boundary vertex would leave the boundary or move along an interior edge, if a
   * boundary face would turn by more than 60 degrees, or if the boundary would move
   * farther than the allowed Hausdorff distance from the input boundary (measured at
   * the input boundary vertices, each attached to its nearest current boundary face).
   * Vertices are removed in the order of Section 4.1: interior ones by the mean volume
   * of their incident tetrahedra (small first), boundary ones by that volume weighted
   * by their Hausdorff distance. Vertices in @p locked (e.g. constrained particles)
   * are never removed.
   */
  MultiTriangulation
  build_multi_triangulation(const mesh::TetMesh             &mesh,
                            const BuilderParameters         &parameters,
                            const std::vector<unsigned int> &locked = {});

  /**
   * Mean-ratio quality of the tetrahedron (a, b, c, d): 1 for the regular one, 0 for a
   * flat one, negative if inverted.
   */
  double
  tet_quality(const mesh::Point3 &a,
              const mesh::Point3 &b,
              const mesh::Point3 &c,
              const mesh::Point3 &d);
} // namespace lacerta::mt
