/**
 * @file
 * The tetrahedron split lookup table (paper, Section 5.2): replaces one tetrahedron
 * crossed by the cut surface with the fewest children that do not cross it, with face
 * triangulations that depend only on global vertex ids so that face-adjacent
 * tetrahedra always agree. Complete cuts (the surface crosses the whole tetrahedron)
 * separate the children into the two sides; partial cuts (the crack front, i.e. the
 * blade or the bottom of the cut, ends inside the tetrahedron) open a crack behind the
 * front and keep the tetrahedron connected ahead of it.
 *
 * This is the hot path of cutting: plain C++17 on raw arrays, no deal.II. See
 * doc/split-table.md for the cases, the diagonal rule and the counts.
 *
 * Local numbering: edges e0=(0,1), e1=(0,2), e2=(0,3), e3=(1,2), e4=(1,3), e5=(2,3);
 * face f is opposite vertex f.
 */
#pragma once

#include <lacerta/cut/tet_decomposition.h>

#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace lacerta::cut
{
  /**
   * Global vertex id, as numbered by the mesh; only its order matters here.
   */
  using VertexId = std::uint64_t;

  /**
   * Default snapping fraction ε: a cut point closer than ε·|edge| to an endpoint snaps
   * onto that endpoint. Allowed range (0, 0.5).
   */
  inline constexpr double default_snap_fraction = 0.05;

  /**
   * Upper bound on the number of children of one split (the table is checked against it
   * when it is built).
   */
  inline constexpr unsigned int max_split_children = 16;

  /**
   * The two local vertices of each local edge, the smaller first.
   */
  inline constexpr std::array<std::array<unsigned int, 2>, 6> tet_edge_vertices = {
    {{{0, 1}}, {{0, 2}}, {{0, 3}}, {{1, 2}}, {{1, 3}}, {{2, 3}}}};

  /**
   * The local edge joining two local vertices (-1 on the diagonal).
   */
  inline constexpr std::array<std::array<int, 4>, 4> tet_edge_of_vertices = {
    {{{-1, 0, 1, 2}}, {{0, -1, 3, 4}}, {{1, 3, -1, 5}}, {{2, 4, 5, -1}}}};

  /**
   * What a node of a child is.
   */
  enum class NodeKind : std::uint8_t
  {
    /** An original vertex of the parent; `index` is the local vertex. */
    vertex,
    /** The cut point on a parent edge; `index` is the local edge. */
    edge_point,
    /** The point where the crack front crosses a parent face; `index` is the face. */
    face_point,
    /** An interior (Steiner) point of the parent, at the centroid of its piece. */
    interior_point
  };

  /**
   * A node of a child tetrahedron.
   */
  struct NodeRef
  {
    NodeKind     kind;
    std::uint8_t index;
    /**
     * For a point on the cut surface that the cut separates: the side (+1 or -1) of the
     * copy this child uses. Edge points of a cut edge are always separated. For a
     * parent vertex lying on the cut surface it is the child's side; whether the two
     * copies of such a vertex are really distinct depends on the whole neighbourhood
     * (the crack may end there) and is for the cutter to decide. 0 otherwise (in
     * particular for face points: they lie on the crack front, which stays connected).
     */
    std::int8_t side;
  };

  /**
   * One child of a split.
   */
  struct Child
  {
    /** The nodes, positively oriented. */
    std::array<NodeRef, 4> nodes;
    /**
     * The side of the cut surface the child lies on (+1 or -1, the sign of the
     * caller's vertex sides), or 0 if it lies ahead of a crack front and has vertices
     * on both sides.
     */
    std::int8_t side;
    /** Bit i is set if the face opposite nodes[i] lies on the cut surface. */
    std::uint8_t cut_faces;
  };

  /**
   * What a split did.
   */
  enum class CutKind : std::uint8_t
  {
    /** No cut: the parent is its only child. */
    none,
    /** The surface only touches the parent at vertices, an edge or a face. */
    touch,
    /** The surface crosses the parent completely; children on two sides. */
    complete,
    /** A crack front ends inside the parent; it is opened behind the front only. */
    partial,
    /**
     * The cut edges do not describe one cut (for example five cut edges): the parent is
     * refined conformingly through all cut points, nothing is separated.
     */
    refinement,
    /** Front points that do not describe a partial cut: nothing was done. */
    unsupported
  };

  /**
   * The cut information of one tetrahedron, as the cutter finds it. Edge cut points and
   * front points must be computed from global data (once per mesh edge and face) so
   * that neighbours receive identical numbers.
   */
  struct TetCut
  {
    /** Global ids of the four vertices; distinct. */
    std::array<VertexId, 4> vertex_ids{};
    /** Rest positions of the four vertices. */
    std::array<Point, 4> points{};
    /**
     * Side of every vertex with respect to the cut surface: +1 or -1, or 0 if the
     * vertex lies on the cut surface (exactly, or snapped; see snap_edge_parameter()).
     */
    std::array<std::int8_t, 4> vertex_side{};
    /** Bit e is set if local edge e is cut. */
    std::uint8_t cut_edges = 0;
    /**
     * For cut edges: position of the cut along the edge, from 0 at the endpoint with
     * the smaller global id to 1 at the other. Clamped to [ε, 1-ε].
     */
    std::array<double, 6> edge_parameter{};
    /** Bit f is set if the crack front crosses local face f (partial cuts only). */
    std::uint8_t front_faces = 0;
    /** Where the crack front crosses each face in front_faces. */
    std::array<Point, 4> front_points{};
  };

  /**
   * The result of split_tetrahedron(): the children and the positions of the new points.
   */
  struct SplitResult
  {
    CutKind                               kind       = CutKind::none;
    unsigned int                          n_children = 0;
    std::array<Child, max_split_children> children{};
    /** Position of the cut point of every cut local edge. */
    std::array<Point, 6> edge_points{};
    /** Position of the front point of every front face. */
    std::array<Point, 4> face_points{};
    /** Position of the interior point, if a child uses one. */
    Point interior_point{};
    /** Index of the table entry used (see split_table_entries()). */
    std::uint16_t entry = 0;
  };

  /**
   * Splits one tetrahedron according to the lookup table. The children are positively
   * oriented, their volumes add up to the parent's, and every face they put on a parent
   * face depends only on the data of that face (its three global ids, the cut points on
   * its edges and its front point), so face-adjacent tetrahedra produce the same
   * triangles. Works for either orientation of the parent. Thread-safe; the table is
   * built on first use. Throws std::invalid_argument if two vertex ids are equal or
   * @p snap_fraction is not in (0, 0.5).
   *
   * @param snap_fraction ε, used to clamp edge parameters to [ε, 1-ε].
   */
  CutKind
  split_tetrahedron(const TetCut &cut,
                    SplitResult  &result,
                    double        snap_fraction = default_snap_fraction);

  /**
   * The length of the shortest edge of the children of @p result (a split of @p cut).
   * For complete cuts it is at least ε·(shortest parent edge)·min(1, sin(smallest face
   * angle)); a partial cut can go below when the plane passes close to a vertex ahead
   * of the crack front (such crossings are not cut yet, so nothing snaps): a cutter
   * that cares can defer that split until the crack leaves the tetrahedron.
   */
  double
  shortest_child_edge(const TetCut &cut, const SplitResult &result);

  /**
   * Where a cut point along an edge ends up after snapping.
   */
  enum class EdgeSnap : std::uint8_t
  {
    /** The edge is cut at the given parameter. */
    inside,
    /** The cut passes through the endpoint with the smaller global id. */
    first_vertex,
    /** The cut passes through the endpoint with the larger global id. */
    second_vertex
  };

  /**
   * The snapping rule for one edge crossing at parameter @p t (from the endpoint with
   * the smaller global id): within ε·|edge| of an endpoint the cut point snaps to it.
   * The cutter applies it once per mesh edge; a vertex that any crossing edge snaps to
   * lies on the cut (side 0), and an edge with an endpoint on the cut is not cut. This
   * keeps every cut point at least ε·|edge| from the edge's ends.
   */
  EdgeSnap
  snap_edge_parameter(double t, double snap_fraction = default_snap_fraction);

  /**
   * The same rule for the crack front along a section side: the front point at
   * parameter @p s between two section corners is kept at least ε from both.
   */
  double
  clamp_front_parameter(double s, double snap_fraction = default_snap_fraction);

  /**
   * The key that orders points for the diagonal rule: a vertex g is (g, g) and the cut
   * point on the edge (a, b) is (min(a,b), max(a,b)), compared lexicographically. It
   * depends on global ids only, so two tetrahedra sharing a face order its points alike.
   */
  std::array<VertexId, 2>
  diagonal_order_key(VertexId a, VertexId b);

  /**
   * The paper's rule for the quadrilateral p0, p1, a, b that remains of the face
   * (p0, p1, z) when the edges z-p0 and z-p1 are cut at b and a: it is split by the
   * diagonal p0-a if p0 or b is the smallest of the four points in diagonal_order_key()
   * order, otherwise by p1-b. Returns true for p0-a.
   */
  bool
  quad_diagonal_through_first(VertexId p0, VertexId p1, VertexId z);

  /**
   * Identity of a point of the cut mesh: what the cutter uses to merge the points that
   * neighbouring splits create.
   */
  struct PointKey
  {
    NodeKind kind = NodeKind::vertex;
    /** Side of the copy for separated edge points, 0 otherwise. */
    std::int8_t side = 0;
    /**
     * Vertex: (id, 0, 0); edge point: its two vertex ids sorted; face point: the
     * face's three vertex ids sorted; interior point: (parent id, 0, 0).
     */
    std::array<VertexId, 3> ids{};

    bool
    operator==(const PointKey &other) const;
    bool
    operator<(const PointKey &other) const;
  };

  /**
   * The key of a node of a child of the tetrahedron with vertex ids @p vertex_ids and
   * id @p parent_id (used only for interior points). Vertices on the cut get side 0:
   * the cutter decides their copies.
   */
  PointKey
  point_key(const std::array<VertexId, 4> &vertex_ids,
            const NodeRef                 &node,
            VertexId                       parent_id);

  /**
   * A table entry as seen from outside, in the canonical frame where local vertex k has
   * the k-th smallest global id: for documentation, statistics and tests.
   */
  struct SplitTableEntry
  {
    CutKind kind;
    /** The case: A, B, C, D, E as in the paper's Figure 1, see doc/split-table.md. */
    std::string name;
    /** Cut edges, vertices on the cut, front faces, in the canonical frame. */
    std::uint8_t cut_edges;
    std::uint8_t cut_vertices;
    std::uint8_t front_faces;
    /** For case B: which diagonal of the cut quadrilateral (0 or 1). */
    std::uint8_t variant;
    unsigned int n_children;
    bool         uses_interior_point;
    /** Children in canonical node ids (0-3 vertices, 4+e and 10+e the two copies of
     * the point on edge e, 16+f face points, 20 the interior point). */
    std::vector<std::array<std::uint8_t, 4>> children;
  };

  /**
   * All entries of the table (built on first use).
   */
  const std::vector<SplitTableEntry> &
  split_table_entries();
} // namespace lacerta::cut
