/**
 * @file
 * A bounding-volume tree over the boundary faces of the deformed object: the first
 * contact of the scalpel (paper, Section 6.1, which used OpenGL picking for it).
 */
#pragma once

#include <lacerta/cut/geometry.h>
#include <lacerta/mesh/tet_mesh.h>

#include <vector>

namespace lacerta
{
  class Archive;
}
namespace lacerta::cut
{
  /**
   * Axis-aligned boxes over the boundary faces, built by median splits. The boxes are
   * inflated by a margin (a quarter of the median face size at the build), so that
   * they stay valid while no vertex of the tree has moved farther than the margin (in
   * any coordinate) from where it was at the last fit; only then are they refitted
   * bottom-up (the topology of a tree does not change with the positions).
   *
   * Faces a cut creates go to a short list searched linearly; at the next refit() a
   * list of 64 or more becomes a tree of its own, merged with the trees of faces added
   * earlier in the manner of a binary counter (Bentley and Saxe's logarithmic method:
   * trees of about 64, 128, 256, ... faces, each face rebuilt O(log m) times when m
   * faces were added). The tree of the mesh's boundary is rebuilt only when the added
   * faces outnumber it. So the cost of a cut follows the faces it creates, not the
   * size of the mesh. Faces that stopped being boundary are skipped at query time.
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
     * faces), no allocation) if a vertex of the trees has moved beyond the margin
     * since the last fit; turns the list of added faces into a tree once it holds 64
     * faces or more (merging the trees of added faces of the same size, or rebuilding
     * everything when the added faces outnumber the mesh's boundary). Otherwise it
     * only compares the positions with those of the last fit. Returns whether the
     * boxes were recomputed or a tree was built.
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
     * and that are still boundary faces of @p mesh, once each and in increasing order
     * of (tet, face), whatever the trees hold: the answer does not depend on how and
     * when the trees were built. The trees' boxes are those of the
     * last build or refit; @p x are the current positions (3 per vertex), passed
     * every time because the array may have moved since (a cut appends particles).
     */
    void
    query(const mesh::TetMesh &mesh,
          const double        *x,
          const Box           &box,
          std::vector<Face>   &hits) const;

    /**
     * As query() with a box, for the faces whose box meets one of @p triangles
     * (Box::meets()): for a thin swept surface, far fewer than those whose box meets
     * the triangles' box. Every face that meets a triangle is among them.
     */
    void
    query(const mesh::TetMesh                       &mesh,
          const double                              *x,
          const std::array<std::array<Point, 3>, 2> &triangles,
          std::vector<Face>                         &hits) const;

    /// Number of faces in the trees and the list of added faces.
    std::size_t
    size() const;

    /// Number of trees of added faces (the logarithmic method's levels in use).
    unsigned int
    n_added_trees() const;

    /// The triangle of @p f at positions @p x.
    static std::array<Point, 3>
    triangle(const Face &f, const double *x);

    /// Writes or reads the state for a checkpoint (see lacerta::Archive).
    void
    serialize(Archive &archive);

  private:
    struct Node
    {
      Box          box;
      unsigned int first, count; // leaf: faces [first, first+count); inner: count = 0
      unsigned int left, right;
    };

    /// One tree: its faces in leaf order and its nodes, children after parents.
    struct Tree
    {
      std::vector<Face> faces;
      std::vector<Node> nodes;

      /// Writes or reads the tree for a checkpoint.
      void
      serialize(Archive &archive);
    };

    /// A face while a tree is built: its box and its centroid (times 3).
    struct Entry
    {
      Face                  face;
      Box                   box;
      std::array<double, 3> centre;
    };

    /// Builds @p tree over @p faces, whose vertices are all tracked, at the positions
    /// of the last fit.
    void
    build_tree(Tree &tree, std::vector<Face> &&faces);

    /// Builds the node of @p tree over `work` [first, first + count) and its subtree.
    unsigned int
    build_node(Tree &tree, unsigned int first, unsigned int count);

    /// Recomputes the boxes of @p tree at the positions of the last fit, inflated by
    /// the margin.
    void
    fit_tree(Tree &tree) const;

    /// Appends the faces of @p tree whose box @p meets accepts (as it accepts their
    /// ancestors' boxes) and that are still boundary.
    template <class Meets>
    static void
    query_tree(const Tree          &tree,
               const mesh::TetMesh &mesh,
               const double        *x,
               const Meets         &meets,
               std::vector<Face>   &hits);

    /// The faces of every tree and of the list whose box @p meets accepts and that are
    /// still boundary, appended to @p hits in increasing (tet, face) order, once each.
    template <class Meets>
    void
    collect(const mesh::TetMesh &mesh,
            const double        *x,
            const Meets         &meets,
            std::vector<Face>   &hits) const;

    /// The box of @p f at positions @p x.
    static Box
    face_box(const Face &f, const double *x);

    /// The box of @p f at the positions of the last fit.
    Box
    fitted_box(const Face &f) const;

    /// Starts watching vertex @p v at position @p x (its position of the last fit).
    void
    track(unsigned int v, const double *x);

    /// Number of faces in the trees of added faces.
    std::size_t
    n_added_faces() const;

    /// Turns the list of added faces into a tree of the logarithmic method.
    void
    merge_added(const mesh::TetMesh &mesh, const double *x);

    /// The tree of the mesh's boundary at the last build.
    Tree boundary;
    /// Trees of added faces: added[k] is empty or holds about 64 * 2^k faces.
    std::vector<Tree> added;
    /// Added faces not yet in a tree.
    std::vector<Face> extra;

    std::vector<Entry>  work;
    std::vector<double> sizes;
    /// The vertices of the trees, once each, their positions at the last fit (3 per
    /// vertex, in the same order), and each vertex's place in them (or invalid).
    std::vector<unsigned int> vertices;
    std::vector<double>       fitted;
    std::vector<unsigned int> slot;
    double                    inflation = 0;
  };
} // namespace lacerta::cut
