/**
 * @file
 * Displacement fields on a TetMesh as the models produce them: values at the vertices
 * (springs, FEM P1) and, for FEM P2, also at the edge midpoints.
 */
#pragma once

#include <lacerta/mesh/tet_mesh.h>

#include <vector>

namespace lacerta::fem
{
  /**
   * A displacement field on a TetMesh, interpolated piecewise linearly (degree 1) or
   * quadratically (degree 2) on every tetrahedron. This is how the reference and the
   * models are compared on different meshes: the error is measured at the nodes of the
   * model's mesh, where the reference field is evaluated.
   */
  struct NodalField
  {
    /// Polynomial degree of the interpolation, 1 or 2.
    unsigned int degree = 1;
    /// Displacement of every vertex, 3 per vertex (m).
    std::vector<double> vertex;
    /// Displacement of every edge midpoint, 3 per edge in mesh.get_edges() order (P2).
    std::vector<double> edge;

    /// The displacement of vertex @p v.
    mesh::Point3
    at_vertex(const unsigned int v) const
    {
      return {vertex[3 * v], vertex[3 * v + 1], vertex[3 * v + 2]};
    }
  };

  /**
   * Evaluates @p field, defined on @p mesh, at every point of @p points (rest
   * coordinates). A point outside the mesh by more than a small tolerance is an Error.
   * A bucket grid keeps the search linear in the number of points.
   */
  std::vector<mesh::Point3>
  evaluate(const mesh::TetMesh             &mesh,
           const NodalField                &field,
           const std::vector<mesh::Point3> &points);

  /**
   * Errors of a vertex displacement field @p u (3 per vertex of the model's mesh)
   * against reference values @p reference at the same vertices.
   */
  struct NodalError
  {
    /// Σ|u - u_ref|² and Σ|u_ref|² over the nodes.
    double squared_error = 0, squared_reference = 0;
    /// Largest |u - u_ref| and largest |u_ref| over the nodes (m).
    double max_error = 0, max_reference = 0;

    /// Adds the nodes of another sample (another time).
    void
    add(const NodalError &other);

    /// Relative L2 error over the nodes, sqrt(Σ|u - u_ref|² / Σ|u_ref|²).
    double
    relative_l2() const;

    /// Largest nodal error divided by the largest reference displacement.
    double
    relative_max() const;
  };

  /// The nodal errors of @p u against @p reference (both 3 values per node).
  NodalError
  nodal_error(const std::vector<double> &u, const std::vector<mesh::Point3> &reference);
} // namespace lacerta::fem
