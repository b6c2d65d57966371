/**
 * @file
 * Minimal tetrahedralisation of a small polyhedron whose boundary triangulation is
 * prescribed: the engine that builds the entries of the split lookup table
 * (split_table.h). It is exposed so that tests can exercise the cases the table never
 * produces, such as a prism whose three quadrilateral diagonals twist around it.
 *
 * Plain C++17, no deal.II: the cutter includes it through split_table.h.
 */
#pragma once

#include <lacerta/mesh/point.h>

#include <array>
#include <cstdint>
#include <optional>
#include <vector>

namespace lacerta::cut
{
  /**
   * A point or vector in three dimensions: the same type as mesh::Point3, whose
   * algebra (mesh/point.h) geometry.h brings into this namespace.
   */
  using Point = mesh::Point3;

  /**
   * A node of a small polyhedron, by an identifier below 32.
   */
  using PieceNode = std::uint8_t;

  /**
   * An oriented triangle of three piece nodes.
   */
  using PieceTriangle = std::array<PieceNode, 3>;

  /**
   * A tetrahedron of four piece nodes, positively oriented when its first three nodes
   * seen from the fourth are counter-clockwise.
   */
  using PieceTetrahedron = std::array<PieceNode, 4>;

  /**
   * A polyhedron to be split into tetrahedra, given combinatorially (its boundary
   * triangles) and by a set of geometric instances on which every tetrahedron of the
   * answer must be positively oriented. Validity for the whole family of geometries the
   * instances sample is what a lookup table needs: the same entry serves every cut
   * position along the edges.
   */
  struct PieceProblem
  {
    /**
     * The nodes that may be used, by identifier (each below 31; 31 is reserved).
     */
    std::vector<PieceNode> nodes;

    /**
     * The boundary, oriented so that the normal (b-a)x(c-a) points into the piece.
     * A slit (a surface the piece is cut along) appears as two sheets with distinct
     * node identifiers for the points that the slit separates.
     */
    std::vector<PieceTriangle> boundary;

    /**
     * For every node identifier, a bit mask of the planar boundary parts the node lies
     * on. A triangle whose three nodes share a bit lies in that plane and can only be
     * a face of the answer if it is one of the boundary triangles.
     */
    std::array<std::uint32_t, 32> plane_mask{};

    /**
     * Geometric instances: position of every node identifier in each instance.
     */
    std::vector<std::array<Point, 32>> samples;
  };

  /**
   * The answer of decompose_piece().
   */
  struct PieceDecomposition
  {
    /**
     * The tetrahedra, positively oriented in every sample.
     */
    std::vector<PieceTetrahedron> tetrahedra;

    /**
     * Whether an interior (Steiner) node was needed; it has identifier
     * `steiner_node` and lies at the average of the piece's nodes.
     */
    bool uses_interior_node = false;
  };

  /**
   * The identifier decompose_piece() gives the interior node when it needs one.
   */
  inline constexpr PieceNode steiner_node = 31;

  /**
   * Searches a tetrahedralisation of the piece with the fewest tetrahedra that uses only
   * the piece's nodes and whose boundary is exactly the prescribed triangles, trying
   * every count up to @p max_tetrahedra. Returns nothing if no such tetrahedralisation
   * exists (the Schönhardt-type twist of a prism is the classical example).
   */
  std::optional<std::vector<PieceTetrahedron>>
  minimal_tetrahedralization(const PieceProblem &problem, unsigned int max_tetrahedra);

  /**
   * Splits the piece into the fewest tetrahedra without new nodes if possible (see
   * minimal_tetrahedralization()); otherwise adds one interior node at the average of
   * the piece's nodes and connects it to every boundary triangle, which is valid for
   * any piece that is star-shaped with respect to that point (every convex piece).
   * Throws std::logic_error if neither works on all samples.
   */
  PieceDecomposition
  decompose_piece(const PieceProblem &problem, unsigned int max_tetrahedra);

  /**
   * Six times the signed volume of the tetrahedron (a, b, c, d).
   */
  double
  signed_volume6(const Point &a, const Point &b, const Point &c, const Point &d);
} // namespace lacerta::cut
