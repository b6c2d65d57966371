/**
 * @file
 * The mutable tetrahedral mesh every subsystem works on.
 */
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace lacerta::mesh
{
  /// A point or vector in 3D, as plain data (the hot loops do not use deal.II types).
  using Point3 = std::array<double, 3>;

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

    /// The unique edges as pairs of vertex ids (first < second), sorted.
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

  private:
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
