/**
 * @file
 * A bounding-volume tree over the boundary faces of the deformed object: the first
 * contact of the scalpel (paper, Section 6.1, which used OpenGL picking for it).
 */
#pragma once

#include <lacerta/cut/geometry.h>
#include <lacerta/mesh/tet_mesh.h>

#include <vector>

namespace lacerta::cut
{
  /**
   * Axis-aligned boxes over the boundary faces, built once by median splits. The boxes
   * are inflated by a margin (a quarter of the median face size at the build), so
   * that they stay valid while no vertex of the tree has moved farther than the
   * margin (in any coordinate) from where it was at the last fit; only then are they
   * refitted bottom-up (the topology of the tree does not change with the positions).
   * Faces a cut creates are kept in a short list that is searched linearly and
   * folded into a rebuild once it is a tenth of the tree, so that the cost of a cut
   * stays proportional to the faces it creates. Faces that stopped being boundary
   * are skipped at query time.
   */
  class BoundaryFaceTree
  {
  public:
    /// A boundary face: its tetrahedron, local face and three vertex ids.
    struct Face
    {
      unsigned int                tet;
      unsigned int                face;
      std::array<unsigned int, 3> vertices;
    };

    /// Builds the tree over the boundary faces of @p mesh at positions @p x (3 per
    /// vertex).
    void
    build(const mesh::TetMesh &mesh, const double *x);

    /**
     * Makes the boxes valid for the positions @p x: recomputes them (O(number of
     * faces), no allocation) if a vertex of the tree has moved beyond the margin since
     * the last fit, or rebuilds the tree if the faces added since the last build are
     * many. Otherwise it only compares the positions with those of the last fit.
     * Returns whether the boxes were recomputed.
     */
    bool
    refit(const mesh::TetMesh &mesh, const double *x);

    /// How far (in every coordinate) a vertex may move before the boxes are refitted.
    double
    margin() const
    {
      return inflation;
    }

    /// Records boundary face (tet, face) of @p mesh, created by a cut.
    void
    add_face(const mesh::TetMesh &mesh, unsigned int tet, unsigned int face);

    /**
     * Appends to @p hits the boundary faces whose box at positions @p x overlaps @p box
     * and that are still boundary faces of @p mesh. The tree's inner boxes are those of
     * the last build or refit; @p x are the current positions (3 per vertex), passed
     * every time because the array may have moved since (a cut appends particles).
     */
    void
    query(const mesh::TetMesh &mesh,
          const double        *x,
          const Box           &box,
          std::vector<Face>   &hits) const;

    /// Number of faces in the tree and the pending list.
    std::size_t
    size() const
    {
      return faces.size() + extra.size();
    }

    /// The triangle of @p f at positions @p x.
    static std::array<Point, 3>
    triangle(const Face &f, const double *x);

  private:
    struct Node
    {
      Box          box;
      unsigned int first, count; // leaf: faces [first, first+count); inner: count = 0
      unsigned int left, right;
    };

    /// A face while the tree is built: its box and its centroid (times 3).
    struct Entry
    {
      Face                  face;
      Box                   box;
      std::array<double, 3> centre;
    };

    /// Builds the node over `work` [first, first + count) and its subtree.
    unsigned int
    build_node(unsigned int first, unsigned int count);

    static Box
    face_box(const Face &f, const double *x);

    /// Recomputes every box for @p x, inflated by the margin, and records @p x as the
    /// positions of the fit.
    void
    fit(const double *x);

    std::vector<Face>   faces;
    std::vector<Entry>  work;
    std::vector<double> sizes;
    std::vector<Face>   extra;
    std::vector<Node>   nodes;
    /// The vertices of `faces`, once each, and their positions at the last fit (3 per
    /// vertex, in the same order).
    std::vector<unsigned int> vertices;
    std::vector<double>       fitted;
    double                    inflation = 0;
  };
} // namespace lacerta::cut
