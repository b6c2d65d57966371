/**
 * @file
 * The mutable tetrahedral mesh every subsystem works on.
 */
#pragma once

#include <lacerta/mesh/point.h>
#include <lacerta/mesh/vertex_stars.h>

#include <array>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

namespace lacerta
{
  class Archive;
}
namespace lacerta::mesh
{
  /// The four vertex ids of a tetrahedron, positively oriented.
  using Tet = std::array<unsigned int, 4>;

  /// Marks a missing neighbour or vertex.
  constexpr unsigned int invalid_index = static_cast<unsigned int>(-1);

  /**
   * One face of a tetrahedron on the boundary of the object.
   */
  struct BoundaryFace
  {
    /// The tetrahedron the face belongs to.
    unsigned int tet;
    /// The local face (opposite local vertex `face`).
    unsigned int face;
    /// The boundary id carried over from the input (0 if the input had none).
    unsigned int boundary_id;
  };

  /**
   * A tetrahedral mesh in its rest configuration, with the connectivity the physics and
   * the cutter need: the neighbour across every face, the boundary faces with their ids,
   * and the unique edges (the springs) with the six edges of every tetrahedron.
   *
   * Conventions: every tetrahedron is positively oriented (its signed volume is > 0);
   * local face f is opposite local vertex f, with vertices face_vertices[f] ordered so
   * that their normal points outward; local edge e joins edge_vertices[e].
   */
  class TetMesh
  {
  public:
    /// Local vertices of the four faces, outward normal (right-hand rule).
    static constexpr std::array<std::array<unsigned int, 3>, 4> face_vertices = {
      {{{1, 2, 3}}, {{0, 3, 2}}, {{0, 1, 3}}, {{0, 2, 1}}}};

    /// Local vertices of the six edges.
    static constexpr std::array<std::array<unsigned int, 2>, 6> edge_vertices = {
      {{{0, 1}}, {{0, 2}}, {{0, 3}}, {{1, 2}}, {{1, 3}}, {{2, 3}}}};

    /**
     * A boundary id given to a face of the input, identified by its three vertex ids in
     * any order.
     */
    struct FaceTag
    {
      std::array<unsigned int, 3> vertices;
      unsigned int                boundary_id;
    };

    TetMesh() = default;

    /**
     * Builds the mesh from vertices and tetrahedra and checks them: coordinates must be
     * finite, no tetrahedron may repeat a vertex or have (near) zero volume, every face
     * must be shared by at most two tetrahedra. Negatively oriented tetrahedra are
     * reoriented. @p source names the input (a file name) in error messages; @p tags
     * carry boundary ids for boundary faces (faces without a tag get id 0).
     */
    TetMesh(std::vector<Point3>         vertices,
            std::vector<Tet>            tets,
            const std::string          &source,
            const std::vector<FaceTag> &tags = {});

    /// Number of vertices (particles).
    unsigned int
    n_vertices() const
    {
      return static_cast<unsigned int>(vertices.size());
    }

    /// Number of tetrahedra.
    unsigned int
    n_tets() const
    {
      return static_cast<unsigned int>(tets.size());
    }

    /// Number of unique edges (springs).
    unsigned int
    n_edges() const
    {
      return static_cast<unsigned int>(edges.size());
    }

    /// Rest position of vertex @p v.
    const Point3 &
    vertex(const unsigned int v) const
    {
      return vertices[v];
    }

    /// All rest positions.
    const std::vector<Point3> &
    get_vertices() const
    {
      return vertices;
    }

    /// The vertex ids of tetrahedron @p t.
    const Tet &
    tet(const unsigned int t) const
    {
      return tets[t];
    }

    /// All tetrahedra.
    const std::vector<Tet> &
    get_tets() const
    {
      return tets;
    }

    /// The tetrahedron across local face @p f of @p t, or invalid_index on the boundary.
    unsigned int
    neighbor(const unsigned int t, const unsigned int f) const
    {
      return neighbors[4 * t + f];
    }

    /**
     * The unique edges as pairs of vertex ids (first < second): sorted when the mesh is
     * built, but no longer after replace_tets() (a cut appends new edges and moves the
     * last into a retired one's id), so look an edge of a tetrahedron up by tet_edges(),
     * not by searching this list.
     */
    const std::vector<std::array<unsigned int, 2>> &
    get_edges() const
    {
      return edges;
    }

    /// The ids of the six edges of tetrahedron @p t, in local edge order.
    const std::array<unsigned int, 6> &
    tet_edges(const unsigned int t) const
    {
      return tet_edge_ids[t];
    }

    /// The faces on the boundary of the object.
    const std::vector<BoundaryFace> &
    get_boundary_faces() const
    {
      return boundary_faces;
    }

    /// Whether vertex @p v lies on a boundary face.
    bool
    is_boundary_vertex(const unsigned int v) const
    {
      return boundary_vertex[v] != 0;
    }

    /// Signed volume of tetrahedron @p t in the rest configuration.
    double
    volume(const unsigned int t) const;

    /// Sum of the volumes of all tetrahedra.
    double
    total_volume() const;

    /// Length of the shortest and of the longest edge.
    std::array<double, 2>
    edge_length_range() const;

    /// The name of the input the mesh came from (for messages).
    const std::string &
    source() const
    {
      return source_name;
    }

    /**
     * Renumbers vertices and tetrahedra along a space-filling (Morton) curve so that
     * particles close in space are close in memory: the spring loop's gathers and
     * scatters then stay in cache. Returns the new index of every old vertex.
     */
    std::vector<unsigned int>
    sort_spatially();

    /**
     * The new index of every vertex along the space-filling (Morton) curve of the
     * vertices' positions, the order sort_spatially() gives (ties keep the current
     * order).
     */
    std::vector<unsigned int>
    spatial_vertex_order() const;

    /**
     * The sum over the edges of the difference of their ends' indices, under the
     * numbering @p new_index (new index of every vertex; the current numbering if
     * empty): how far apart in memory the particles that springs join are.
     */
    double
    index_spread(const std::vector<unsigned int> &new_index = {}) const;

    /**
     * Gives every vertex v the index @p new_index[v] (a permutation of the vertices),
     * in its tetrahedra and edges (an edge's ends stay ordered) and in the local
     * updates' stars. Tetrahedra, edges and boundary faces keep their ids. Costs one
     * pass over the mesh.
     */
    void
    renumber_vertices(const std::vector<unsigned int> &new_index);

    /**
     * What replace_tets() did to the ids, so that arrays indexed by edge or by
     * tetrahedron (the springs, a force model's per-cell data) can follow: first
     * `n_added_edges` edges were appended, then every pair (to, from) of `edge_moves`,
     * in order, copied edge `from` (the last one) into slot `to` and dropped the last
     * slot. When fewer tetrahedra came than went, every pair (to, from) of `tet_moves`
     * moved tetrahedron `from` (from the end) into the free slot `to`, in order.
     */
    struct Update
    {
      unsigned int                             n_added_edges = 0;
      std::vector<std::array<unsigned int, 2>> edge_moves;
      std::vector<std::array<unsigned int, 2>> tet_moves;
    };

    /**
     * Builds the vertex-to-tetrahedra incidence and the boundary face slots that local
     * updates need. Only the cutter calls it: a scene without cuts never pays for it.
     * Idempotent.
     */
    void
    enable_local_updates();

    /**
     * Makes room for @p n_vertices vertices and @p n_tets tetrahedra (edges and
     * boundary faces in proportion), so that add_vertex() and replace_tets() copy no
     * array while the mesh stays within that size: a local update then costs nothing
     * proportional to the mesh.
     */
    void
    reserve(unsigned int n_vertices, unsigned int n_tets);

    /// Whether enable_local_updates() was called.
    bool
    has_local_updates() const
    {
      return !vertex_tets.empty() || vertices.empty();
    }

    /// The tetrahedra incident to vertex @p v (needs enable_local_updates()).
    VertexStars::Star
    tets_of_vertex(const unsigned int v) const
    {
      return vertex_tets[v];
    }

    /// The id of the edge joining @p a and @p b, or invalid_index (needs local updates).
    unsigned int
    find_edge(unsigned int a, unsigned int b) const;

    /**
     * Calls @p visit (t, e) for the tetrahedra t that hold both @p a and @p b, with e
     * the local edge joining them, until it returns true (needs local updates). The
     * cells come in the order of the smaller of the two stars.
     */
    template <typename Visit>
    void
    visit_tets_with_edge(const unsigned int a, const unsigned int b, Visit &&visit) const
    {
      // Any tetrahedron with both ends has the edge: search the smaller star (a vertex
      // just made by a cut has an empty one). A cell of u's star has u, so it has the
      // edge if it also has w: four comparisons instead of two for each of six edges.
      const bool         from_a = vertex_tets.star_size(a) <= vertex_tets.star_size(b);
      const unsigned int u = from_a ? a : b, w = from_a ? b : a;
      for (const unsigned int t : vertex_tets[u])
      {
        const Tet &q = tets[t];
        // Without short-circuits: which cells of the star hold w follows no pattern
        // a branch predictor learns.
        if (!(int(q[0] == w) | int(q[1] == w) | int(q[2] == w) | int(q[3] == w)))
          continue;
        unsigned int j = 0;
        while (q[j] != w)
          ++j;
        unsigned int i = 0;
        while (q[i] != u)
          ++i;
        if (i > j)
          std::swap(i, j);
        static_assert(
          []
          {
            for (unsigned int e = 0; e < 6; ++e)
              if (edge_vertices[e][0] + edge_vertices[e][1]
                    - (edge_vertices[e][0] == 0 ? 1 : 0)
                  != e)
                return false;
            return true;
          }(),
          "local edge (i, j) is numbered i + j - [i == 0]");
        if (visit(t, i + j - (i == 0 ? 1 : 0)))
          return;
      }
    }

    /// Appends the tetrahedra containing both @p a and @p b to @p out (local updates).
    void
    tets_around_edge(unsigned int               a,
                     unsigned int               b,
                     std::vector<unsigned int> &out) const;

    /**
     * The boundary id of face @p f of tetrahedron @p t, or invalid_index if it is not
     * a boundary face (needs local updates).
     */
    unsigned int
    boundary_id(const unsigned int t, const unsigned int f) const
    {
      const unsigned int slot = boundary_slot[4 * t + f];
      return slot == invalid_index ? invalid_index : boundary_faces[slot].boundary_id;
    }

    /// Appends a vertex at rest position @p x and returns its id (local updates).
    unsigned int
    add_vertex(const Point3 &x);

    /**
     * Replaces the tetrahedra @p removed by @p added, updating neighbours, boundary
     * faces, edges and boundary flags locally: the cost is proportional to the number
     * of tetrahedra involved and the size of their vertex stars, not to the mesh size.
     * The first added tetrahedra take the slots of the removed ones, the others are
     * appended; when fewer come than go, the last tetrahedra fill the slots left
     * (`update.tet_moves`). The added ones' final ids are returned in @p added_ids.
     * A face of an added tetrahedron that finds no neighbour becomes a boundary face
     * with id @p face_boundary_ids[k][f]. The caller guarantees that the result is
     * conforming and that every face between a removed and a surviving tetrahedron
     * is a face of an added one (the cutter does, by deciding every cut from global
     * ids; a level of detail, by swapping whole fragments of the MT).
     */
    void
    replace_tets(const std::vector<unsigned int>                &removed,
                 const std::vector<Tet>                         &added,
                 const std::vector<std::array<unsigned int, 4>> &face_boundary_ids,
                 std::vector<unsigned int>                      &added_ids,
                 Update                                         &update);

    /**
     * Removes the vertices @p dead, which no tetrahedron may hold any more (an error
     * otherwise), keeping the ids compact: every pair (to, from) appended to @p moves
     * moved vertex `from` (the last one) into the free slot `to`, in order, and renamed
     * it in its tetrahedra and edges (an edge's ends stay ordered). Local: the cost is
     * that of the moved vertices' stars (needs local updates).
     */
    void
    remove_vertices(std::vector<unsigned int>                 dead,
                    std::vector<std::array<unsigned int, 2>> &moves);

    /// Writes or reads the state for a checkpoint (see lacerta::Archive).
    void
    serialize(Archive &archive);

  private:
    /// Working arrays of replace_tets(), kept so that an update allocates nothing
    /// once they have grown; `vertex_stamp` (per vertex) and `edge_stamp` (per edge id)
    /// mark the vertices and old edges seen by the current update, `fresh_stamp` the
    /// vertices only new tets hold, `tet_stamp` the removed tets.
    struct ReplaceScratch
    {
      std::vector<std::array<unsigned int, 6>> new_edge_ids;
      /// Open-addressing table of the edges of the new tets seen so far: (a, b, id).
      std::vector<std::array<unsigned int, 3>> created;
      /// Open-addressing table of faces by sorted vertex triple: (a, b, c, 4 t + f).
      std::vector<std::array<unsigned int, 4>> faces;
      std::vector<std::array<unsigned int, 3>> old_edges;
      std::vector<unsigned int>                dead, refresh, vertex_stamp, edge_stamp;
      std::vector<unsigned int>                fresh_stamp, tet_stamp;
      unsigned int                             stamp = 0;

      /// Notes vertex @p v (in `refresh`) unless the current update did.
      void
      note_vertex(const unsigned int v)
      {
        if (vertex_stamp[v] != stamp)
        {
          vertex_stamp[v] = stamp;
          refresh.push_back(v);
        }
      }
    };

    /// replace_tets(), stage 1: the edge ids of the @p added tets (`new_edge_ids`),
    /// those of existing edges kept, new edges appended to `edges`.
    void
    number_new_edges(const std::vector<unsigned int> &removed,
                     const std::vector<Tet>          &added,
                     Update                          &update);
    /// Stage 2: a new stamp for the update's marks.
    void
    start_replace_marks();
    /// Stage 3: takes the @p removed tets out of the edge counts, the boundary faces,
    /// their neighbours' links and the vertex stars; lists their edges (`old_edges`)
    /// and the faces whose neighbour survives (`faces`).
    void
    take_out_tets(const std::vector<unsigned int> &removed, std::size_t n_added);
    /// Stage 4: puts the @p added tets into the removed ones' slots, then at the end,
    /// into @p added_ids; their edges and stars.
    void
    put_in_tets(const std::vector<unsigned int> &removed,
                const std::vector<Tet>          &added,
                std::vector<unsigned int>       &added_ids);
    /// Stage 5: the new tets' neighbours across faces that `faces` knows.
    void
    link_new_faces(const std::vector<unsigned int> &added_ids);
    /// Stage 6: the new tets' faces still open: a surviving cell's face, or a
    /// boundary face with id @p face_ids[k][f].
    void
    close_open_faces(const std::vector<std::array<unsigned int, 4>> &face_ids,
                     const std::vector<unsigned int>                &added_ids);
    /// Stage 7: retires the old edges no tetrahedron uses any more (into
    /// `update.edge_moves`).
    void
    retire_dead_edges(Update &update);
    /// Stage 8: the boundary flags of the vertices the update involved.
    void
    refresh_boundary_flags();
    /// Stage 9: when fewer tets came than went, fills the free slots from the end
    /// (into `update.tet_moves` and @p added_ids).
    void
    fill_free_slots(const std::vector<unsigned int> &removed,
                    std::size_t                      n_added,
                    std::vector<unsigned int>       &added_ids,
                    Update                          &update);

    /// Removes boundary face (t, f) if it is one.
    void
    remove_boundary_face(unsigned int t, unsigned int f);

    /// Adds boundary face (t, f) with @p id.
    void
    add_boundary_face(unsigned int t, unsigned int f, unsigned int id);

    /// Moves tetrahedron @p from into the free slot @p to (replace_tets()).
    void
    move_tet(unsigned int from, unsigned int to);

    /// For local updates: the tetrahedra around every vertex.
    VertexStars vertex_tets;
    /// For local updates: index into boundary_faces of face 4 t + f, or invalid_index.
    std::vector<unsigned int> boundary_slot;
    /// For local updates: the number of tetrahedra that hold each edge.
    std::vector<unsigned int> edge_uses;

    /// Rebuilds neighbours, boundary faces, edges and boundary flags from the tets.
    void
    build_connectivity(const std::vector<FaceTag> &tags);

    std::vector<Point3>                      vertices;
    std::vector<Tet>                         tets;
    std::vector<unsigned int>                neighbors;
    std::vector<std::array<unsigned int, 2>> edges;
    std::vector<std::array<unsigned int, 6>> tet_edge_ids;
    std::vector<BoundaryFace>                boundary_faces;
    std::vector<std::uint8_t>                boundary_vertex;
    std::string                              source_name;
    ReplaceScratch                           replace_scratch;
  };

  /**
   * Signed volume of the tetrahedron (a, b, c, d): positive if (b-a, c-a, d-a) is a
   * right-handed frame.
   */
  double
  signed_volume(const Point3 &a, const Point3 &b, const Point3 &c, const Point3 &d);

  /**
   * Why the tetrahedron @p cell of @p vertices cannot be used, or an empty string if it
   * can: it repeats a vertex, or its volume is (near) zero against the cube of its
   * longest edge. A repeated vertex is named by its id in @p cell, a flat tetrahedron by
   * the coordinates of its vertices. Readers call this before
   * building a TetMesh so that their messages can name the cell as the file numbers it.
   * The ids in @p cell must be valid indices into @p vertices.
   */
  std::string
  degeneracy(const std::vector<Point3> &vertices, const Tet &cell);
} // namespace lacerta::mesh
