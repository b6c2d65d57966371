#include <lacerta/base/archive.h>
#include <lacerta/base/exceptions.h>
#include <lacerta/mesh/tet_mesh.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <numeric>

namespace lacerta::mesh
{
  double
  signed_volume(const Point3 &a, const Point3 &b, const Point3 &c, const Point3 &d)
  {
    const double u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
    const double v[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
    const double w[3] = {d[0] - a[0], d[1] - a[1], d[2] - a[2]};
    return (u[0] * (v[1] * w[2] - v[2] * w[1]) - u[1] * (v[0] * w[2] - v[2] * w[0])
            + u[2] * (v[0] * w[1] - v[1] * w[0]))
           / 6.0;
  }


  namespace
  {
    std::string
    describe_point(const Point3 &p)
    {
      std::ostringstream s;
      s.precision(8);
      s << "(" << p[0] << ", " << p[1] << ", " << p[2] << ")";
      return s.str();
    }


    double
    longest_edge(const std::vector<Point3> &vertices, const Tet &t)
    {
      double longest = 0;
      for (const auto &e : TetMesh::edge_vertices)
      {
        const Point3 &a = vertices[t[e[0]]];
        const Point3 &b = vertices[t[e[1]]];
        longest = std::max(longest, std::hypot(b[0] - a[0], b[1] - a[1], b[2] - a[2]));
      }
      return longest;
    }


    /// Sorted copy of three ids, the key that identifies a face from either side.
    std::array<unsigned int, 3>
    sorted(std::array<unsigned int, 3> ids)
    {
      std::sort(ids.begin(), ids.end());
      return ids;
    }


    /// The smaller of @p x and @p y, computed without a branch (GCC compiles
    /// std::min of these to one, and which is smaller follows no pattern).
    inline unsigned int
    lesser(const unsigned int x, const unsigned int y)
    {
      return y ^ ((x ^ y) & (0u - static_cast<unsigned int>(x < y)));
    }


    /// Sets @p table to @p size entries of invalid_index (every byte 0xff) in one
    /// memset: assign() writes the entries' ids one at a time, and the update's
    /// tables are cleared at every update.
    template <std::size_t n>
    void
    clear_table(std::vector<std::array<unsigned int, n>> &table, const std::size_t size)
    {
      static_assert(invalid_index == 0xffffffffu);
      table.resize(size);
      std::memset(static_cast<void *>(table.data()), 0xff, size * sizeof(table[0]));
    }


    /// A face's three vertex ids, sorted: the key that names it from either side.
    using FaceKey = std::array<unsigned int, 3>;


    /// The key of local face @p f of @p cell, sorted without branches.
    inline FaceKey
    face_key(const Tet &cell, const unsigned int f)
    {
      const unsigned int a = cell[TetMesh::face_vertices[f][0]],
                         b = cell[TetMesh::face_vertices[f][1]],
                         c = cell[TetMesh::face_vertices[f][2]];
      // x ^ y ^ lesser(x, y) is the greater one.
      const unsigned int low_ab = lesser(a, b), high_ab = a ^ b ^ low_ab;
      const unsigned int low = lesser(low_ab, c), high = high_ab ^ c ^ lesser(high_ab, c);
      return {{low, a ^ b ^ c ^ low ^ high, high}};
    }


    /// The slot of edge (@p a, @p b), a < b, in the open-addressing table @p table (a
    /// power of two of entries (a, b, id), never full): its entry, or the empty slot
    /// where it goes.
    inline std::array<unsigned int, 3> &
    edge_slot(std::vector<std::array<unsigned int, 3>> &table,
              const unsigned int                        a,
              const unsigned int                        b)
    {
      const std::size_t mask = table.size() - 1;
      std::size_t       h    = ((std::size_t(a) * 0x9E3779B97F4A7C15ULL)
                       ^ (std::size_t(b) * 0xC2B2AE3D27D4EB4FULL))
                      >> 20;
      for (h &= mask;; h = (h + 1) & mask)
      {
        auto &slot = table[h];
        if (slot[2] == invalid_index || (slot[0] == a && slot[1] == b))
          return slot;
      }
    }


    /// The slot of face @p key in the open-addressing table @p table (a power of two
    /// of entries (a, b, c, 4 t + f), never full): its entry, or the empty slot where
    /// it goes.
    inline std::array<unsigned int, 4> &
    face_slot(std::vector<std::array<unsigned int, 4>> &table, const FaceKey &key)
    {
      const std::size_t mask = table.size() - 1;
      std::size_t       h    = (std::size_t(key[0]) * 0x9E3779B97F4A7C15ULL
                       + std::size_t(key[1]) * 0xC2B2AE3D27D4EB4FULL
                       + std::size_t(key[2]) * 0x165667B19E3779F9ULL)
                      >> 20;
      for (h &= mask;; h = (h + 1) & mask)
      {
        // Stop at the face or at an empty slot (slot[0] + 1 wraps to 0): one test
        // of a product, as GCC splits a disjunction of comparisons into branches
        // again, and which of the two it is follows no pattern.
        auto              &slot = table[h];
        const unsigned int differs =
          (slot[0] ^ key[0]) | (slot[1] ^ key[1]) | (slot[2] ^ key[2]);
        if (std::uint64_t(differs) * std::uint32_t(slot[0] + 1u) == 0)
          return slot;
      }
    }
  } // namespace


  std::string
  degeneracy(const std::vector<Point3> &vertices, const Tet &cell)
  {
    std::ostringstream problem;
    problem.precision(8);
    for (unsigned int i = 0; i < 4; ++i)
      for (unsigned int j = 0; j < i; ++j)
        if (cell[i] == cell[j])
        {
          problem << "it repeats vertex " << cell[i] << " at "
                  << describe_point(vertices[cell[i]]);
          return problem.str();
        }
    const double volume = signed_volume(vertices[cell[0]],
                                        vertices[cell[1]],
                                        vertices[cell[2]],
                                        vertices[cell[3]]);
    const double h      = longest_edge(vertices, cell);
    // A tetrahedron whose volume is negligible against the cube of its longest edge
    // has no stiffness across its height and would make the time step collapse.
    // (Also true when two distinct vertices share a position: then h may still be > 0
    // but the volume is exactly zero.)
    if (!(std::abs(volume) > 1e-12 * h * h * h))
    {
      problem << "its volume is zero (its vertices " << describe_point(vertices[cell[0]])
              << ", " << describe_point(vertices[cell[1]]) << ", "
              << describe_point(vertices[cell[2]]) << ", "
              << describe_point(vertices[cell[3]]) << " lie in a plane)";
      return problem.str();
    }
    return "";
  }


  TetMesh::TetMesh(std::vector<Point3>         vertices_in,
                   std::vector<Tet>            tets_in,
                   const std::string          &source,
                   const std::vector<FaceTag> &tags)
      : vertices(std::move(vertices_in))
      , tets(std::move(tets_in))
      , source_name(source)
  {
    if (tets.empty())
      throw_error("Mesh '", source_name, "' has no tetrahedra.");

    for (unsigned int v = 0; v < vertices.size(); ++v)
      for (const double x : vertices[v])
        if (!std::isfinite(x))
          throw_error("Mesh '",
                      source_name,
                      "': vertex ",
                      v,
                      " has a coordinate that is not a finite number ",
                      describe_point(vertices[v]),
                      ".");

    for (unsigned int t = 0; t < tets.size(); ++t)
    {
      Tet &cell = tets[t];
      for (unsigned int i = 0; i < 4; ++i)
      {
        if (cell[i] >= vertices.size())
          throw_error("Mesh '",
                      source_name,
                      "': cell ",
                      t,
                      " refers to vertex ",
                      cell[i],
                      " but the mesh has only ",
                      vertices.size(),
                      " vertices.");
      }
      const std::string problem = degeneracy(vertices, cell);
      if (!problem.empty())
        throw_error(
          "Mesh '", source_name, "': cell ", t, " is degenerate: ", problem, ".");
      const double volume = signed_volume(vertices[cell[0]],
                                          vertices[cell[1]],
                                          vertices[cell[2]],
                                          vertices[cell[3]]);
      if (volume < 0)
        std::swap(cell[2], cell[3]);
    }

    // Vertices no tetrahedron uses (nodes of surface elements only, say) would be
    // particles without mass: drop them. The others keep their order, so that vertex
    // ids match the input's and the boundary tags below are renumbered like the tets.
    std::vector<unsigned int> compact(vertices.size(), invalid_index);
    for (const Tet &cell : tets)
      for (const unsigned int v : cell)
        compact[v] = 0;
    unsigned int n_used = 0;
    for (unsigned int &index : compact)
      if (index != invalid_index)
        index = n_used++;
    if (n_used < vertices.size())
    {
      std::vector<Point3> used(n_used);
      for (unsigned int v = 0; v < vertices.size(); ++v)
        if (compact[v] != invalid_index)
          used[compact[v]] = vertices[v];
      vertices = std::move(used);
      for (Tet &cell : tets)
        for (unsigned int &v : cell)
          v = compact[v];
    }
    std::vector<FaceTag> used_tags;
    for (const FaceTag &tag : tags)
      if (tag.vertices[0] < compact.size() && tag.vertices[1] < compact.size()
          && tag.vertices[2] < compact.size() && compact[tag.vertices[0]] != invalid_index
          && compact[tag.vertices[1]] != invalid_index
          && compact[tag.vertices[2]] != invalid_index)
        used_tags.push_back(
          {{compact[tag.vertices[0]], compact[tag.vertices[1]], compact[tag.vertices[2]]},
           tag.boundary_id});

    build_connectivity(used_tags);
  }


  void
  TetMesh::build_connectivity(const std::vector<FaceTag> &tags)
  {
    const bool had_local_updates = !vertex_tets.empty();
    vertex_tets.clear();
    boundary_slot.clear();
    const unsigned int n_tets = tets.size();

    // Faces: sort (key, owner) so that the two sides of an interior face are adjacent.
    struct FaceEntry
    {
      std::array<unsigned int, 3> key;
      unsigned int                owner; // 4 * tet + local face
    };
    std::vector<FaceEntry> faces(4 * n_tets);
    for (unsigned int t = 0; t < n_tets; ++t)
      for (unsigned int f = 0; f < 4; ++f)
        faces[4 * t + f] = {sorted({tets[t][face_vertices[f][0]],
                                    tets[t][face_vertices[f][1]],
                                    tets[t][face_vertices[f][2]]}),
                            4 * t + f};
    std::sort(faces.begin(),
              faces.end(),
              [](const FaceEntry &a, const FaceEntry &b)
              { return a.key < b.key || (a.key == b.key && a.owner < b.owner); });

    std::vector<FaceTag> sorted_tags = tags;
    for (auto &tag : sorted_tags)
      tag.vertices = sorted(tag.vertices);
    std::sort(sorted_tags.begin(),
              sorted_tags.end(),
              [](const FaceTag &a, const FaceTag &b) { return a.vertices < b.vertices; });

    neighbors.assign(4 * n_tets, invalid_index);
    boundary_faces.clear();
    for (std::size_t i = 0; i < faces.size();)
    {
      std::size_t j = i + 1;
      while (j < faces.size() && faces[j].key == faces[i].key)
        ++j;
      if (j - i > 2)
        throw_error("Mesh '",
                    source_name,
                    "' is not a manifold: the face with vertices ",
                    faces[i].key[0],
                    ", ",
                    faces[i].key[1],
                    ", ",
                    faces[i].key[2],
                    " is shared by ",
                    j - i,
                    " cells (cells ",
                    faces[i].owner / 4,
                    ", ",
                    faces[i + 1].owner / 4,
                    ", ",
                    faces[i + 2].owner / 4,
                    ").");
      if (j - i == 2)
      {
        neighbors[faces[i].owner]     = faces[i + 1].owner / 4;
        neighbors[faces[i + 1].owner] = faces[i].owner / 4;
      }
      else
      {
        const auto tag =
          std::lower_bound(sorted_tags.begin(),
                           sorted_tags.end(),
                           faces[i].key,
                           [](const FaceTag &a, const std::array<unsigned int, 3> &key)
                           { return a.vertices < key; });
        const unsigned int id =
          (tag != sorted_tags.end() && tag->vertices == faces[i].key) ? tag->boundary_id
                                                                      : 0;
        boundary_faces.push_back({faces[i].owner / 4, faces[i].owner % 4, id});
      }
      i = j;
    }
    std::sort(boundary_faces.begin(),
              boundary_faces.end(),
              [](const BoundaryFace &a, const BoundaryFace &b)
              { return a.tet < b.tet || (a.tet == b.tet && a.face < b.face); });

    boundary_vertex.assign(vertices.size(), 0);
    for (const BoundaryFace &bf : boundary_faces)
      for (const unsigned int lv : face_vertices[bf.face])
        boundary_vertex[tets[bf.tet][lv]] = 1;

    // Edges: the same trick with (sorted pair, owner).
    std::vector<std::pair<std::array<unsigned int, 2>, unsigned int>> edge_list(6
                                                                                * n_tets);
    for (unsigned int t = 0; t < n_tets; ++t)
      for (unsigned int e = 0; e < 6; ++e)
      {
        unsigned int a = tets[t][edge_vertices[e][0]];
        unsigned int b = tets[t][edge_vertices[e][1]];
        if (a > b)
          std::swap(a, b);
        edge_list[6 * t + e] = {{{a, b}}, 6 * t + e};
      }
    std::sort(edge_list.begin(), edge_list.end());
    edges.clear();
    tet_edge_ids.assign(n_tets, {});
    for (const auto &[key, owner] : edge_list)
    {
      if (edges.empty() || edges.back() != key)
        edges.push_back(key);
      tet_edge_ids[owner / 6][owner % 6] = edges.size() - 1;
    }
    if (had_local_updates)
      enable_local_updates();
  }

  double
  TetMesh::volume(const unsigned int t) const
  {
    const Tet &c = tets[t];
    return signed_volume(vertices[c[0]], vertices[c[1]], vertices[c[2]], vertices[c[3]]);
  }


  double
  TetMesh::total_volume() const
  {
    double sum = 0;
    for (unsigned int t = 0; t < tets.size(); ++t)
      sum += volume(t);
    return sum;
  }


  std::array<double, 2>
  TetMesh::edge_length_range() const
  {
    std::array<double, 2> range = {std::numeric_limits<double>::max(), 0.0};
    for (const auto &e : edges)
    {
      const Point3 &a = vertices[e[0]];
      const Point3 &b = vertices[e[1]];
      const double  l = std::hypot(b[0] - a[0], b[1] - a[1], b[2] - a[2]);
      range[0]        = std::min(range[0], l);
      range[1]        = std::max(range[1], l);
    }
    return range;
  }


  namespace
  {
    /// Spreads the lower 21 bits of x so that two zero bits follow each bit.
    std::uint64_t
    spread_bits(std::uint64_t x)
    {
      x &= 0x1fffff;
      x = (x | x << 32) & 0x1f00000000ffffULL;
      x = (x | x << 16) & 0x1f0000ff0000ffULL;
      x = (x | x << 8) & 0x100f00f00f00f00fULL;
      x = (x | x << 4) & 0x10c30c30c30c30c3ULL;
      x = (x | x << 2) & 0x1249249249249249ULL;
      return x;
    }


    /// Morton keys of points in the bounding box of @p points.
    std::vector<std::uint64_t>
    morton_keys(const std::vector<Point3> &points)
    {
      Point3 lo = points[0], hi = points[0];
      for (const Point3 &p : points)
        for (unsigned int d = 0; d < 3; ++d)
        {
          lo[d] = std::min(lo[d], p[d]);
          hi[d] = std::max(hi[d], p[d]);
        }
      const double extent =
        std::max({hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2], 1e-300});
      std::vector<std::uint64_t> keys(points.size());
      for (std::size_t i = 0; i < points.size(); ++i)
      {
        std::uint64_t key = 0;
        for (unsigned int d = 0; d < 3; ++d)
          key |= spread_bits(static_cast<std::uint64_t>((points[i][d] - lo[d]) / extent
                                                        * double((1 << 21) - 1)))
                 << d;
        keys[i] = key;
      }
      return keys;
    }


    /// The permutation that sorts @p keys (stable, so ties keep the input order).
    std::vector<unsigned int>
    sorting_permutation(const std::vector<std::uint64_t> &keys)
    {
      std::vector<unsigned int> order(keys.size());
      std::iota(order.begin(), order.end(), 0u);
      std::stable_sort(order.begin(),
                       order.end(),
                       [&](unsigned int a, unsigned int b) { return keys[a] < keys[b]; });
      return order;
    }
  } // namespace


  std::vector<unsigned int>
  TetMesh::sort_spatially()
  {
    // Keep the boundary ids across the renumbering.
    std::vector<FaceTag> tags;
    for (const BoundaryFace &bf : boundary_faces)
      if (bf.boundary_id != 0)
        tags.push_back({{tets[bf.tet][face_vertices[bf.face][0]],
                         tets[bf.tet][face_vertices[bf.face][1]],
                         tets[bf.tet][face_vertices[bf.face][2]]},
                        bf.boundary_id});

    const std::vector<unsigned int> new_index = spatial_vertex_order();
    std::vector<Point3>             new_vertices(vertices.size());
    for (unsigned int v = 0; v < new_index.size(); ++v)
      new_vertices[new_index[v]] = vertices[v];
    vertices = std::move(new_vertices);
    for (Tet &t : tets)
      for (unsigned int &v : t)
        v = new_index[v];
    for (FaceTag &tag : tags)
      for (unsigned int &v : tag.vertices)
        v = new_index[v];

    std::vector<Point3> centroids(tets.size());
    for (unsigned int t = 0; t < tets.size(); ++t)
      for (unsigned int d = 0; d < 3; ++d)
        centroids[t][d] = 0.25
                          * (vertices[tets[t][0]][d] + vertices[tets[t][1]][d]
                             + vertices[tets[t][2]][d] + vertices[tets[t][3]][d]);
    const std::vector<unsigned int> tet_order =
      sorting_permutation(morton_keys(centroids));
    std::vector<Tet> new_tets(tets.size());
    for (unsigned int i = 0; i < tet_order.size(); ++i)
      new_tets[i] = tets[tet_order[i]];
    tets = std::move(new_tets);

    build_connectivity(tags);
    return new_index;
  }


  std::vector<unsigned int>
  TetMesh::spatial_vertex_order() const
  {
    const std::vector<unsigned int> order = sorting_permutation(morton_keys(vertices));
    std::vector<unsigned int>       new_index(order.size());
    for (unsigned int i = 0; i < order.size(); ++i)
      new_index[order[i]] = i;
    return new_index;
  }


  double
  TetMesh::index_spread(const std::vector<unsigned int> &new_index) const
  {
    double sum = 0;
    for (const auto &[a, b] : edges)
      sum += new_index.empty() ? double(b) - double(a)
                               : std::abs(double(new_index[a]) - double(new_index[b]));
    return sum;
  }


  void
  TetMesh::renumber_vertices(const std::vector<unsigned int> &new_index)
  {
    const std::size_t n      = vertices.size();
    const auto        refuse = [n]()
    {
      throw_error("TetMesh::renumber_vertices: the new indices are no permutation of "
                  "the mesh's ",
                  n,
                  " vertices.");
    };
    if (new_index.size() != n)
      refuse();
    std::vector<bool> taken(n, false);
    for (const unsigned int w : new_index)
    {
      if (w >= n || taken[w])
        refuse();
      taken[w] = true;
    }
    std::vector<Point3>       moved(n);
    std::vector<std::uint8_t> moved_boundary(n);
    for (std::size_t v = 0; v < n; ++v)
    {
      moved[new_index[v]]          = vertices[v];
      moved_boundary[new_index[v]] = boundary_vertex[v];
    }
    vertices        = std::move(moved);
    boundary_vertex = std::move(moved_boundary);
    for (Tet &t : tets)
      for (unsigned int &v : t)
        v = new_index[v];
    for (auto &edge : edges)
    {
      const unsigned int a = new_index[edge[0]], b = new_index[edge[1]];
      edge = {{std::min(a, b), std::max(a, b)}};
    }
    if (!vertex_tets.empty())
    {
      vertex_tets.clear();
      vertex_tets.resize(n);
      for (unsigned int t = 0; t < tets.size(); ++t)
        for (const unsigned int v : tets[t])
          vertex_tets.insert(v, t);
    }
  }


  void
  TetMesh::enable_local_updates()
  {
    if (!vertex_tets.empty())
      return;
    vertex_tets.resize(vertices.size());
    for (unsigned int t = 0; t < tets.size(); ++t)
      for (const unsigned int v : tets[t])
        vertex_tets.insert(v, t);
    boundary_slot.assign(4 * tets.size(), invalid_index);
    for (unsigned int i = 0; i < boundary_faces.size(); ++i)
      boundary_slot[4 * boundary_faces[i].tet + boundary_faces[i].face] = i;
    edge_uses.assign(edges.size(), 0);
    for (const auto &ids : tet_edge_ids)
      for (const unsigned int id : ids)
        ++edge_uses[id];
  }


  void
  TetMesh::reserve(const unsigned int n_vertices, const unsigned int n_tets)
  {
    const double growth =
      tets.empty() ? 1.0 : std::max(1.0, double(n_tets) / double(tets.size()));
    vertices.reserve(n_vertices);
    boundary_vertex.reserve(n_vertices);
    tets.reserve(n_tets);
    tet_edge_ids.reserve(n_tets);
    neighbors.reserve(4 * std::size_t(n_tets));
    edges.reserve(std::size_t(growth * double(edges.size())));
    // A cut adds boundary faces faster than tetrahedra: twice the proportion.
    boundary_faces.reserve(std::size_t(2 * growth * double(boundary_faces.size())));
    if (!vertex_tets.empty())
    {
      vertex_tets.reserve(n_vertices);
      boundary_slot.reserve(4 * std::size_t(n_tets));
      // replace_tets()'s stamps too, sized now: otherwise the first updates fill them
      // and copy them as they grow, a mesh-sized cost (384 kB at 59535 tetrahedra)
      // in the middle of a cut.
      const std::size_t n_edges = std::size_t(growth * double(edges.size()));
      replace_scratch.vertex_stamp.reserve(n_vertices);
      replace_scratch.vertex_stamp.resize(vertices.size(), 0);
      edge_uses.reserve(n_edges);
      replace_scratch.edge_stamp.reserve(n_edges);
      replace_scratch.edge_stamp.resize(edges.size(), 0);
      replace_scratch.fresh_stamp.reserve(n_vertices);
      replace_scratch.fresh_stamp.resize(vertices.size(), 0);
      replace_scratch.tet_stamp.reserve(n_tets);
      replace_scratch.tet_stamp.resize(tets.size(), 0);
    }
  }


  unsigned int
  TetMesh::find_edge(const unsigned int a, const unsigned int b) const
  {
    unsigned int id = invalid_index;
    visit_tets_with_edge(a,
                         b,
                         [&](const unsigned int t, const unsigned int e)
                         {
                           id = tet_edge_ids[t][e];
                           return true;
                         });
    return id;
  }


  void
  TetMesh::tets_around_edge(const unsigned int         a,
                            const unsigned int         b,
                            std::vector<unsigned int> &out) const
  {
    for (const unsigned int t : vertex_tets[a])
    {
      const Tet &q = tets[t];
      if (q[0] == b || q[1] == b || q[2] == b || q[3] == b)
        out.push_back(t);
    }
  }


  unsigned int
  TetMesh::add_vertex(const Point3 &x)
  {
    vertices.push_back(x);
    vertex_tets.resize(vertices.size());
    boundary_vertex.push_back(0);
    return static_cast<unsigned int>(vertices.size() - 1);
  }


  void
  TetMesh::remove_boundary_face(const unsigned int t, const unsigned int f)
  {
    const unsigned int slot = boundary_slot[4 * t + f];
    if (slot == invalid_index)
      return;
    const BoundaryFace last                 = boundary_faces.back();
    boundary_faces[slot]                    = last;
    boundary_slot[4 * last.tet + last.face] = slot;
    boundary_faces.pop_back();
    boundary_slot[4 * t + f] = invalid_index;
  }


  void
  TetMesh::add_boundary_face(const unsigned int t,
                             const unsigned int f,
                             const unsigned int id)
  {
    boundary_slot[4 * t + f] = static_cast<unsigned int>(boundary_faces.size());
    boundary_faces.push_back({t, f, id});
  }


  void
  TetMesh::replace_tets(const std::vector<unsigned int>                &removed,
                        const std::vector<Tet>                         &added,
                        const std::vector<std::array<unsigned int, 4>> &face_ids,
                        std::vector<unsigned int>                      &added_ids,
                        Update                                         &update)
  {
    if (face_ids.size() != added.size())
      throw_error("TetMesh::replace_tets: ",
                  added.size(),
                  " tetrahedra come with ",
                  face_ids.size(),
                  " lists of face boundary ids.");
    update.n_added_edges = 0;
    update.edge_moves.clear();
    update.tet_moves.clear();
    number_new_edges(removed, added, update);
    start_replace_marks();
    take_out_tets(removed, added.size());
    put_in_tets(removed, added, added_ids);
    link_new_faces(added_ids);
    close_open_faces(face_ids, added_ids);
    retire_dead_edges(update);
    refresh_boundary_flags();
    fill_free_slots(removed, added.size(), added_ids, update);
  }


  void
  TetMesh::number_new_edges(const std::vector<unsigned int> &removed,
                            const std::vector<Tet>          &added,
                            Update                          &update)
  {
    // Edge ids of the new tets, looked up while the old tets are still in place, so
    // that an edge that survives keeps its id (and its spring). Edges not found are
    // numbered in the order they first appear. A small hash table of the edges seen
    // so far (found or made) answers their repetitions (an inner edge of the new
    // cells appears in several of them) without searching a star again.
    ReplaceScratch &scratch      = replace_scratch;
    auto           &new_edge_ids = scratch.new_edge_ids;
    new_edge_ids.resize(added.size());
    // The table first takes the removed cells' edges with their ids: most edges of
    // the new cells that already exist are theirs, found without a star search (an
    // edge id names one edge, so the id is the one the search would find). The new
    // cells have about 1.5 distinct edges each, but a few cells apart from each other
    // have up to six: the table has room for six per cell involved (8 slots per cell,
    // so it never fills and the probing always ends), and, cleared at every update,
    // evicts little from the cache.
    std::size_t table_size = 16;
    while (table_size < 8 * (added.size() + removed.size()))
      table_size *= 2;
    auto &created = scratch.created;
    clear_table(created, table_size);
    for (const unsigned int r : removed)
      for (unsigned int e = 0; e < 6; ++e)
      {
        const unsigned int x = tets[r][edge_vertices[e][0]],
                           y = tets[r][edge_vertices[e][1]];
        const unsigned int a = lesser(x, y), b = x ^ y ^ a;
        edge_slot(created, a, b) = {{a, b, tet_edge_ids[r][e]}};
      }
    for (std::size_t k = 0; k < added.size(); ++k)
      for (unsigned int e = 0; e < 6; ++e)
      {
        const unsigned int x = added[k][edge_vertices[e][0]],
                           y = added[k][edge_vertices[e][1]];
        // Ordered without a branch (which end is smaller follows no pattern).
        const unsigned int a = lesser(x, y), b = x ^ y ^ a;
        auto              &slot = edge_slot(created, a, b);
        if (slot[2] == invalid_index)
        {
          // Not an edge of a removed cell: one of a surviving cell, or a new one.
          unsigned int id = find_edge(a, b);
          if (id == invalid_index)
          {
            id = static_cast<unsigned int>(edges.size());
            edges.push_back({{a, b}});
            ++update.n_added_edges;
          }
          slot = {{a, b, id}};
        }
        new_edge_ids[k][e] = slot[2];
      }
  }


  void
  TetMesh::start_replace_marks()
  {
    // A new stamp marks what this update sees; when the stamps wrap, every mark is
    // cleared once.
    ReplaceScratch &scratch = replace_scratch;
    if (++scratch.stamp == 0)
    {
      std::fill(scratch.vertex_stamp.begin(), scratch.vertex_stamp.end(), 0u);
      std::fill(scratch.edge_stamp.begin(), scratch.edge_stamp.end(), 0u);
      std::fill(scratch.fresh_stamp.begin(), scratch.fresh_stamp.end(), 0u);
      std::fill(scratch.tet_stamp.begin(), scratch.tet_stamp.end(), 0u);
      scratch.stamp = 1;
    }
    // Vertices whose boundary flag may change: those of the old and the new tets.
    scratch.vertex_stamp.resize(vertices.size(), 0);
    scratch.fresh_stamp.resize(vertices.size(), 0);
    scratch.refresh.clear();
  }


  void
  TetMesh::take_out_tets(const std::vector<unsigned int> &removed,
                         const std::size_t                n_added)
  {
    // Take the old tets out: stars, boundary faces, neighbours' back links. Their
    // edges, once each (an edge id names one edge), are candidates for retirement.
    // An edge of a new tet lives on: marking those first leaves as candidates only
    // the edges that just the remaining old tets may still hold.
    ReplaceScratch &scratch   = replace_scratch;
    auto           &old_edges = scratch.old_edges;
    old_edges.clear();
    scratch.edge_stamp.resize(edges.size(), 0);
    edge_uses.resize(edges.size(), 0);
    for (const auto &ids : scratch.new_edge_ids)
      for (const unsigned int id : ids)
        scratch.edge_stamp[id] = scratch.stamp;
    // Faces by key, for the neighbours (link_new_faces()): the removed cells' faces
    // whose neighbour survives go in now, the new cells' faces later. The table holds
    // at most four faces per cell involved, so it never fills and probing always ends.
    std::size_t face_table_size = 16;
    while (face_table_size <= 4 * (n_added + removed.size()))
      face_table_size *= 2;
    auto &face_table = scratch.faces;
    clear_table(face_table, face_table_size);
    scratch.tet_stamp.resize(tets.size(), 0);
    for (const unsigned int r : removed)
      scratch.tet_stamp[r] = scratch.stamp;
    for (const unsigned int r : removed)
    {
      for (unsigned int e = 0; e < 6; ++e)
      {
        const unsigned int id = tet_edge_ids[r][e];
        --edge_uses[id];
        if (scratch.edge_stamp[id] == scratch.stamp)
          continue;
        scratch.edge_stamp[id] = scratch.stamp;
        unsigned int a = tets[r][edge_vertices[e][0]], b = tets[r][edge_vertices[e][1]];
        old_edges.push_back({{std::min(a, b), std::max(a, b), id}});
      }
      for (const unsigned int v : tets[r])
        scratch.note_vertex(v);
      for (unsigned int f = 0; f < 4; ++f)
      {
        remove_boundary_face(r, f);
        const unsigned int n = neighbors[4 * r + f];
        if (n != invalid_index)
          for (unsigned int g = 0; g < 4; ++g)
            if (neighbors[4 * n + g] == r)
            {
              neighbors[4 * n + g] = invalid_index;
              if (scratch.tet_stamp[n] != scratch.stamp)
              {
                const FaceKey key          = face_key(tets[r], f);
                face_slot(face_table, key) = {{key[0], key[1], key[2], 4 * n + g}};
              }
            }
        neighbors[4 * r + f] = invalid_index;
      }
    }
    // The removed tets leave the stars of their vertices (so far exactly the noted
    // ones), all of a star's at once.
    for (const unsigned int v : scratch.refresh)
      vertex_tets.erase_marked(v,
                               [&](const unsigned int t)
                               { return scratch.tet_stamp[t] == scratch.stamp; });
  }


  void
  TetMesh::put_in_tets(const std::vector<unsigned int> &removed,
                       const std::vector<Tet>          &added,
                       std::vector<unsigned int>       &added_ids)
  {
    // Put the new tets in: the first ones into the removed ones' slots, the others
    // appended (the arrays grow once, not once per tet). Slots left free are filled
    // at the end (fill_free_slots()).
    ReplaceScratch &scratch = replace_scratch;
    added_ids.resize(added.size());
    const std::size_t n_old = tets.size(),
                      n_new =
                        n_old + std::max(added.size(), removed.size()) - removed.size();
    tets.resize(n_new);
    tet_edge_ids.resize(n_new);
    neighbors.resize(4 * n_new, invalid_index);
    boundary_slot.resize(4 * n_new, invalid_index);
    for (std::size_t k = 0; k < added.size(); ++k)
    {
      const unsigned int slot = k < removed.size()
                                  ? removed[k]
                                  : static_cast<unsigned int>(n_old + k - removed.size());
      added_ids[k]            = slot;
      if (k < removed.size())
        scratch.tet_stamp[slot] = 0;
      tets[slot]         = added[k];
      tet_edge_ids[slot] = scratch.new_edge_ids[k];
      for (const unsigned int id : scratch.new_edge_ids[k])
        ++edge_uses[id];
      for (const unsigned int v : added[k])
      {
        // A vertex whose star is empty now is held by new cells only.
        if (vertex_tets.star_size(v) == 0)
          scratch.fresh_stamp[v] = scratch.stamp;
        vertex_tets.insert(v, slot);
        scratch.note_vertex(v);
      }
    }
  }


  void
  TetMesh::link_new_faces(const std::vector<unsigned int> &added_ids)
  {
    // Neighbours, by the faces' sorted vertex triples (a face has at most two cells,
    // the caller guarantees it, and a neighbour shares all three vertices). The other
    // cell of a new cell's face is another new cell, or a surviving cell that was the
    // neighbour of a removed one across that face (take_out_tets() listed it), or,
    // rarely, a surviving cell whose face was on the boundary (close_open_faces()). A
    // table lookup instead of a star scan per face: the scan's membership tests were
    // the update's most mispredicted branches.
    auto &face_table = replace_scratch.faces;
    for (const unsigned int t : added_ids)
      for (unsigned int f = 0; f < 4; ++f)
      {
        const FaceKey key  = face_key(tets[t], f);
        auto         &slot = face_slot(face_table, key);
        // Whether the face is already there (half of them) follows no pattern:
        // selects instead of branches. A hit leaves the entry as it is; a miss
        // enters the face and writes invalid_index where it already is
        // (masks: GCC compiles the selects of `hit ? :` to branches).
        const unsigned int hit = 0u - static_cast<unsigned int>(slot[0] != invalid_index);
        const unsigned int own = 4 * t + f;
        const unsigned int other = (slot[3] & hit) | (own & ~hit);
        slot                     = {{key[0], key[1], key[2], other}};
        neighbors[own]           = (other / 4) | ~hit;
        neighbors[other]         = t | ~hit;
      }
  }


  void
  TetMesh::close_open_faces(const std::vector<std::array<unsigned int, 4>> &face_ids,
                            const std::vector<unsigned int>                &added_ids)
  {
    // The faces left are boundary faces unless a surviving cell has the same three
    // vertices (the new cells then close a boundary). In the order of the new cells
    // and their faces, as the boundary face list's order depends on it. A face with a
    // vertex that only new cells hold is not searched for.
    const ReplaceScratch &scratch = replace_scratch;
    for (std::size_t k = 0; k < added_ids.size(); ++k)
    {
      const unsigned int t = added_ids[k];
      for (unsigned int f = 0; f < 4; ++f)
      {
        if (neighbors[4 * t + f] != invalid_index)
          continue;
        unsigned int v[3]  = {tets[t][face_vertices[f][0]],
                              tets[t][face_vertices[f][1]],
                              tets[t][face_vertices[f][2]]};
        unsigned int other = invalid_index, other_face = 0;
        if (scratch.fresh_stamp[v[0]] != scratch.stamp
            && scratch.fresh_stamp[v[1]] != scratch.stamp
            && scratch.fresh_stamp[v[2]] != scratch.stamp)
        {
          for (unsigned int i = 1; i < 3; ++i)
            if (vertex_tets.star_size(v[i]) < vertex_tets.star_size(v[0]))
              std::swap(v[0], v[i]);
          for (const unsigned int s : vertex_tets[v[0]])
          {
            if (s == t)
              continue;
            const Tet &q = tets[s];
            // Without short-circuits: most cells of the star lack v[1] or v[2], at
            // positions no branch predictor learns.
            const auto has = [&](const unsigned int w)
            { return (q[0] == w) | (q[1] == w) | (q[2] == w) | (q[3] == w); };
            if (has(v[1]) & has(v[2]))
            {
              other = s;
              for (unsigned int g = 0; g < 4; ++g)
                if (q[g] != v[0] && q[g] != v[1] && q[g] != v[2])
                  other_face = g;
              break;
            }
          }
        }
        if (other == invalid_index)
          add_boundary_face(t, f, face_ids[k][f]);
        else
        {
          neighbors[4 * t + f]              = other;
          neighbors[4 * other + other_face] = t;
          remove_boundary_face(other, other_face);
        }
      }
    }
  }


  void
  TetMesh::retire_dead_edges(Update &update)
  {
    // Retire the edges no tetrahedron uses any more, largest id first, so that the
    // last slot moved into a hole is always a live edge. The counts of uses answer
    // without searching a star for a cell with both ends (a dead edge's search read
    // the whole star).
    auto &dead = replace_scratch.dead;
    dead.clear();
    for (const auto &e : replace_scratch.old_edges)
      if (edge_uses[e[2]] == 0)
        dead.push_back(e[2]);
    std::sort(dead.rbegin(), dead.rend());
    for (const unsigned int r : dead)
    {
      const unsigned int last = static_cast<unsigned int>(edges.size() - 1);
      if (r != last)
      {
        edges[r]     = edges[last];
        edge_uses[r] = edge_uses[last];
        // Every cell with both ends holds the moved edge, at one local edge.
        visit_tets_with_edge(edges[r][0],
                             edges[r][1],
                             [&](const unsigned int t, const unsigned int e)
                             {
                               tet_edge_ids[t][e] = r;
                               return false;
                             });
      }
      update.edge_moves.push_back({{r, last}});
      edges.pop_back();
      edge_uses.pop_back();
    }
  }


  void
  TetMesh::refresh_boundary_flags()
  {
    // Boundary flags of every vertex involved, once each.
    for (const unsigned int v : replace_scratch.refresh)
    {
      if (v >= boundary_vertex.size())
        boundary_vertex.resize(v + 1, 0);
      std::uint8_t on_boundary = 0;
      for (const unsigned int t : vertex_tets[v])
      {
        // A face without a neighbour that holds v (not the one opposite v), tested
        // for the four faces at once: which of them is open follows no pattern.
        const unsigned int *n = &neighbors[4 * t];
        const Tet          &q = tets[t];
        if (((n[0] == invalid_index) & (q[0] != v))
            | ((n[1] == invalid_index) & (q[1] != v))
            | ((n[2] == invalid_index) & (q[2] != v))
            | ((n[3] == invalid_index) & (q[3] != v)))
        {
          on_boundary = 1;
          break;
        }
      }
      boundary_vertex[v] = on_boundary;
    }
  }


  void
  TetMesh::fill_free_slots(const std::vector<unsigned int> &removed,
                           const std::size_t                n_added,
                           std::vector<unsigned int>       &added_ids,
                           Update                          &update)
  {
    // Fewer tets came than went: the slots still marked removed are filled from the
    // end, a free slot below the new size with the last tet that is not free.
    if (n_added >= removed.size())
      return;
    ReplaceScratch &scratch = replace_scratch;
    auto           &holes   = scratch.dead;
    holes.assign(removed.begin() + n_added, removed.end());
    std::sort(holes.begin(), holes.end());
    const std::size_t n_kept = tets.size() - holes.size();
    std::size_t       from   = tets.size();
    for (const unsigned int to : holes)
    {
      if (to >= n_kept)
        break;
      do
        --from;
      while (scratch.tet_stamp[from] == scratch.stamp);
      move_tet(static_cast<unsigned int>(from), to);
      update.tet_moves.push_back({{to, static_cast<unsigned int>(from)}});
    }
    for (const auto &[to, moved] : update.tet_moves)
      for (unsigned int &id : added_ids)
        if (id == moved)
          id = to;
    tets.resize(n_kept);
    tet_edge_ids.resize(n_kept);
    neighbors.resize(4 * n_kept);
    boundary_slot.resize(4 * n_kept);
    scratch.tet_stamp.resize(n_kept);
  }


  void
  TetMesh::move_tet(const unsigned int from, const unsigned int to)
  {
    tets[to]         = tets[from];
    tet_edge_ids[to] = tet_edge_ids[from];
    for (unsigned int f = 0; f < 4; ++f)
    {
      const unsigned int n    = neighbors[4 * from + f];
      neighbors[4 * to + f]   = n;
      neighbors[4 * from + f] = invalid_index;
      if (n != invalid_index)
        for (unsigned int g = 0; g < 4; ++g)
          if (neighbors[4 * n + g] == from)
            neighbors[4 * n + g] = to;
      const unsigned int slot     = boundary_slot[4 * from + f];
      boundary_slot[4 * to + f]   = slot;
      boundary_slot[4 * from + f] = invalid_index;
      if (slot != invalid_index)
        boundary_faces[slot].tet = to;
    }
    for (const unsigned int v : tets[to])
    {
      vertex_tets.erase(v, from);
      vertex_tets.insert(v, to);
    }
  }


  void
  TetMesh::remove_vertices(std::vector<unsigned int>                 dead,
                           std::vector<std::array<unsigned int, 2>> &moves)
  {
    // Largest first, so that the last vertex moved into a free slot is always a live
    // one (every dead vertex above it is gone already).
    std::sort(dead.rbegin(), dead.rend());
    dead.erase(std::unique(dead.begin(), dead.end()), dead.end());
    std::vector<unsigned int> star;
    for (const unsigned int r : dead)
    {
      if (r >= vertices.size() || vertex_tets.star_size(r) != 0)
        throw_error("TetMesh::remove_vertices: vertex ",
                    r,
                    " of ",
                    vertices.size(),
                    " is still held by a tetrahedron or does not exist.");
      const unsigned int last = static_cast<unsigned int>(vertices.size() - 1);
      if (r != last)
      {
        vertices[r]        = vertices[last];
        boundary_vertex[r] = boundary_vertex[last];
        star.assign(vertex_tets[last].begin(), vertex_tets[last].end());
        for (const unsigned int t : star)
        {
          vertex_tets.insert(r, t);
          for (unsigned int &w : tets[t])
            if (w == last)
              w = r;
          for (const unsigned int id : tet_edge_ids[t])
          {
            auto &edge = edges[id];
            if (edge[0] != last && edge[1] != last)
              continue;
            const unsigned int other = edge[0] == last ? edge[1] : edge[0];
            edge                     = {{std::min(other, r), std::max(other, r)}};
          }
        }
        vertex_tets.erase_marked(last, [](const unsigned int) { return true; });
        moves.push_back({{r, last}});
      }
      vertices.pop_back();
      boundary_vertex.pop_back();
      vertex_tets.resize(vertices.size());
    }
    replace_scratch.vertex_stamp.resize(vertices.size());
    replace_scratch.fresh_stamp.resize(vertices.size());
  }


  void
  TetMesh::serialize(Archive &archive)
  {
    archive.section("mesh");
    archive(vertices, tets, neighbors, edges, tet_edge_ids, boundary_faces);
    archive(boundary_vertex, source_name, vertex_tets, boundary_slot, edge_uses);
  }
} // namespace lacerta::mesh
