#include <lacerta/cut/geometry.h>
#include <lacerta/cut/split_table.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <random>
#include <stdexcept>
#include <tuple>

// The table is generated, not typed in: every configuration is enumerated from planar
// sections of a reference tetrahedron (in the canonical frame where vertex k has the
// k-th smallest global id), its boundary is triangulated with the face rules, and the
// fewest children are found by an exhaustive search (tet_decomposition.cc) that accepts
// only tetrahedra positive on every sampled section. That makes minimality a checked
// property instead of a claim, and keeps one source of truth for the face rules.

namespace lacerta::cut
{
  namespace
  {
    // ---------------------------------------------------------------------------------
    // Canonical node identifiers: 0-3 the vertices, 4+e and 10+e the two copies of the
    // cut point of edge e (on the side of its first and of its second vertex; a
    // refinement uses 4+e alone), 16+f the front point of face f, 20 the interior point.
    constexpr std::uint8_t
    first_copy(const unsigned e)
    {
      return static_cast<std::uint8_t>(4 + e);
    }
    constexpr std::uint8_t
    second_copy(const unsigned e)
    {
      return static_cast<std::uint8_t>(10 + e);
    }
    constexpr std::uint8_t
    face_node(const unsigned f)
    {
      return static_cast<std::uint8_t>(16 + f);
    }
    constexpr std::uint8_t interior_node = 20;
    constexpr unsigned     n_node_ids    = 21;
    constexpr std::uint8_t cut_plane_bit = 16; // plane mask bit of the cut surface
    constexpr std::uint8_t no_vertex     = 0xFF;

    unsigned
    popcount(unsigned m)
    {
      unsigned c = 0;
      for (; m; m &= m - 1)
        ++c;
      return c;
    }

    // Faces (bit f) that contain a vertex or an edge.
    unsigned
    faces_of_vertex(const unsigned v)
    {
      return 0xFu & ~(1u << v);
    }

    unsigned
    faces_of_edge(const unsigned e)
    {
      return 0xFu & ~(1u << tet_edge_vertices[e][0]) & ~(1u << tet_edge_vertices[e][1]);
    }

    // ---------------------------------------------------------------------------------
    // Generation.

    // A corner of a planar section: a vertex on the cut, or the cut point of an edge.
    struct Corner
    {
      bool     is_vertex;
      unsigned index;
    };

    // One geometric instance of a configuration.
    struct Sample
    {
      std::array<Point, 32> x{};      // position of every canonical node id
      Point                 normal{}; // unit normal of the cut plane
      Point                 origin{}; // a point on it
      std::array<double, 4> d{};      // signed distance of the vertices, 0 on the cut
      std::vector<Corner>   corners;  // crack or section polygon, counter-clockwise
    };

    struct Configuration
    {
      CutKind             kind;
      std::uint8_t        edges = 0, vertices = 0, faces = 0;
      std::string         name;
      std::vector<Sample> samples;
    };

    using Key = std::uint16_t;

    Key
    make_key(const unsigned edges, const unsigned vertices, const unsigned faces)
    {
      return static_cast<Key>(edges | (vertices << 6) | (faces << 10));
    }

    std::array<Point, 4>
    reference_tetrahedron()
    {
      // Regular and positively oriented.
      return {{{1, 1, 1}, {-1, -1, 1}, {-1, 1, -1}, {1, -1, -1}}};
    }

    Point
    corner_position(const Corner &c, const Sample &s)
    {
      return c.is_vertex ? s.x[c.index] : s.x[first_copy(c.index)];
    }

    // Sorts corners counter-clockwise around the sample's normal.
    void
    sort_corners(std::vector<Corner>      &corners,
                 const std::vector<Point> &positions,
                 const Point              &normal)
    {
      Point c{0, 0, 0};
      for (const auto &p : positions)
        c = add(c, scale(1.0 / positions.size(), p));
      const Point                                 u = sub(positions[0], c);
      const Point                                 w = cross(normal, u);
      std::vector<std::pair<double, std::size_t>> angle;
      for (std::size_t i = 0; i < positions.size(); ++i)
      {
        const Point r = sub(positions[i], c);
        angle.emplace_back(std::atan2(dot(w, r), dot(u, r)), i);
      }
      std::sort(angle.begin(), angle.end());
      std::vector<Corner> sorted;
      for (const auto &a : angle)
        sorted.push_back(corners[a.second]);
      corners = sorted;
    }

    /// A pattern of vertex sides of a plane against the reference tetrahedron: each
    /// vertex +1, -1 or 0 (on the plane), and the masks of each kind.
    struct SidePattern
    {
      std::array<int, 4> side{};
      unsigned           zmask = 0, pmask = 0, nmask = 0;
    };


    /// Side pattern number @p code (base 3, one digit per vertex).
    SidePattern
    side_pattern(const unsigned code)
    {
      SidePattern p;
      for (unsigned v = 0, c = code; v < 4; ++v, c /= 3)
        p.side[v] = static_cast<int>(c % 3) - 1;
      for (unsigned v = 0; v < 4; ++v)
        (p.side[v] == 0 ? p.zmask : (p.side[v] > 0 ? p.pmask : p.nmask)) |= 1u << v;
      return p;
    }


    /// The configuration of a plane that touches the tetrahedron at the vertices
    /// @p zmask (or misses it), added once.
    void
    add_touch_configuration(std::map<Key, Configuration> &configurations,
                            const unsigned                zmask)
    {
      const auto X   = reference_tetrahedron();
      const Key  key = make_key(0, zmask, 0);
      auto      &cfg = configurations[key];
      if (!cfg.samples.empty())
        return;
      const unsigned n = popcount(zmask);
      cfg.kind         = n == 0 ? CutKind::none : CutKind::touch;
      cfg.vertices     = static_cast<std::uint8_t>(zmask);
      cfg.name =
        n == 0 ? "none" : (n == 1 ? "touch-v" : (n == 2 ? "touch-e" : "touch-f"));
      Sample s;
      for (unsigned v = 0; v < 4; ++v)
        s.x[v] = X[v];
      cfg.samples.push_back(s);
    }


    /// A random plane realising @p pattern, through its first three @p corners
    /// (vertices, or random points on the @p crossing edges), into @p s with the
    /// section's sorted corners; false if the plane drawn does not realise it well
    /// (nearly degenerate, or a vertex or a cut point too close to it).
    bool
    random_section(const SidePattern         &pattern,
                   const std::vector<Corner> &corners,
                   const unsigned             crossing,
                   std::mt19937              &rng,
                   Sample                    &s)
    {
      const auto                             X = reference_tetrahedron();
      std::uniform_real_distribution<double> param(0.02, 0.98);
      for (unsigned v = 0; v < 4; ++v)
        s.x[v] = X[v];
      std::array<Point, 3> through;
      for (unsigned k = 0; k < 3; ++k)
      {
        const Corner &c = corners[k];
        if (c.is_vertex)
          through[k] = X[c.index];
        else
        {
          const unsigned i = tet_edge_vertices[c.index][0],
                         j = tet_edge_vertices[c.index][1];
          through[k]       = lerp(X[i], X[j], param(rng));
        }
      }
      Point normal = cross(sub(through[1], through[0]), sub(through[2], through[0]));
      const double length = norm(normal);
      if (length < 1e-6)
        return false;
      normal      = scale(1.0 / length, normal);
      s.origin    = through[0];
      bool   ok   = true;
      double flip = 0;
      for (unsigned v = 0; v < 4; ++v)
      {
        s.d[v] = dot(normal, sub(X[v], s.origin));
        if (pattern.side[v] == 0)
        {
          s.d[v] = 0;
          continue;
        }
        if (std::abs(s.d[v]) < 1e-3)
          ok = false;
        const double f = s.d[v] * pattern.side[v] > 0 ? 1 : -1;
        if (flip == 0)
          flip = f;
        else if (flip != f)
          ok = false;
      }
      if (!ok)
        return false;
      // Orient the normal towards the pattern's + side.
      s.normal = scale(flip, normal);
      for (unsigned v = 0; v < 4; ++v)
        s.d[v] *= flip;
      for (unsigned e = 0; e < 6; ++e)
        if (crossing & (1u << e))
        {
          const unsigned i = tet_edge_vertices[e][0], j = tet_edge_vertices[e][1];
          const double   t = s.d[i] / (s.d[i] - s.d[j]);
          if (t < 0.02 || t > 0.98)
            ok = false;
          s.x[first_copy(e)] = s.x[second_copy(e)] = lerp(X[i], X[j], t);
        }
      if (!ok)
        return false;
      std::vector<Point> positions;
      for (const auto &c : corners)
        positions.push_back(corner_position(c, s));
      s.corners = corners;
      sort_corners(s.corners, positions, s.normal);
      return true;
    }


    /// Adds sample @p s to the complete cut through the @p crossing edges and the
    /// @p zmask vertices.
    void
    add_complete_sample(std::map<Key, Configuration> &configurations,
                        const unsigned                crossing,
                        const unsigned                zmask,
                        const Sample                 &s)
    {
      const Key key = make_key(crossing, zmask, 0);
      auto     &cfg = configurations[key];
      cfg.kind      = CutKind::complete;
      cfg.edges     = static_cast<std::uint8_t>(crossing);
      cfg.vertices  = static_cast<std::uint8_t>(zmask);
      cfg.name      = std::string(s.corners.size() == 3 ? "A" : "B")
                 + std::string(popcount(zmask) >= 1 ? "-v" : "")
                 + std::string(popcount(zmask) >= 2 ? "v" : "");
      cfg.samples.push_back(s);
    }


    /// Adds the partial cuts of section @p s (whose vertices on the plane are
    /// @p zmask): every crack that is a run of consecutive corners reaching all those
    /// vertices, with the front crossing the two section sides that leave the run.
    void
    add_partial_samples(std::map<Key, Configuration> &configurations,
                        const unsigned                zmask,
                        const Sample                 &s,
                        std::mt19937                 &rng)
    {
      std::uniform_real_distribution<double> param(0.02, 0.98);
      const auto                            &ring = s.corners;
      const unsigned                         m    = static_cast<unsigned>(ring.size());
      for (unsigned start = 0; start < m; ++start)
        for (unsigned length_run = 1; length_run < m; ++length_run)
        {
          std::vector<Corner> run;
          unsigned            run_edges = 0, run_vertices = 0;
          for (unsigned k = 0; k < length_run; ++k)
          {
            const Corner &c = ring[(start + k) % m];
            run.push_back(c);
            (c.is_vertex ? run_vertices : run_edges) |= 1u << c.index;
          }
          if (run_vertices != zmask)
            continue; // a vertex on the plane that the crack does not reach
          const Corner &last     = run.back();
          const Corner &next     = ring[(start + length_run) % m];
          const Corner &first    = run.front();
          const Corner &before   = ring[(start + m - 1) % m];
          const auto    faces_of = [](const Corner &c)
          { return c.is_vertex ? faces_of_vertex(c.index) : faces_of_edge(c.index); };
          const unsigned f_after  = faces_of(last) & faces_of(next);
          const unsigned f_before = faces_of(before) & faces_of(first);
          if (popcount(f_after) != 1 || popcount(f_before) != 1 || f_after == f_before)
            continue;
          Sample      p        = s;
          const Point a_last   = corner_position(last, s),
                      a_next   = corner_position(next, s);
          const Point a_first  = corner_position(first, s),
                      a_before = corner_position(before, s);
          unsigned fa = 0, fb = 0;
          while (!(f_after & (1u << fa)))
            ++fa;
          while (!(f_before & (1u << fb)))
            ++fb;
          p.x[face_node(fa)] = lerp(a_last, a_next, param(rng));
          p.x[face_node(fb)] = lerp(a_first, a_before, param(rng));
          // Crack polygon: the run, then the two front points.
          p.corners     = run;
          const Key key = make_key(run_edges, run_vertices, f_after | f_before);
          auto     &cfg = configurations[key];
          cfg.kind      = CutKind::partial;
          cfg.edges     = static_cast<std::uint8_t>(run_edges);
          cfg.vertices  = static_cast<std::uint8_t>(run_vertices);
          cfg.faces     = static_cast<std::uint8_t>(f_after | f_before);
          cfg.name      = std::string(1, static_cast<char>('C' + length_run - 1))
                     + std::string(popcount(run_vertices) >= 1 ? "-v" : "")
                     + std::string(popcount(run_vertices) >= 2 ? "v" : "");
          if (cfg.samples.size() < 48)
            cfg.samples.push_back(p);
        }
    }


    // Adds the configurations of every planar section of the reference tetrahedron: for
    // each pattern of vertex sides (+, -, or on the plane), random planes realising it,
    // the complete cut and every partial cut whose crack is a run of consecutive section
    // corners, with the front crossing the two section sides that leave the run.
    void
    enumerate_sections(std::map<Key, Configuration> &configurations, std::mt19937 &rng)
    {
      for (unsigned code = 0; code < 81; ++code)
      {
        const SidePattern pattern = side_pattern(code);
        // Each pattern once up to a global flip: the lowest off-plane vertex is +.
        const unsigned off = pattern.pmask | pattern.nmask;
        if (off == 0)
          continue;
        const unsigned lowest = off & (~off + 1);
        if (!(pattern.pmask & lowest))
          continue;
        if (pattern.nmask == 0)
        {
          add_touch_configuration(configurations, pattern.zmask);
          continue;
        }
        unsigned crossing = 0;
        for (unsigned e = 0; e < 6; ++e)
        {
          const unsigned i = tet_edge_vertices[e][0], j = tet_edge_vertices[e][1];
          if (pattern.side[i] * pattern.side[j] < 0)
            crossing |= 1u << e;
        }
        std::vector<Corner> corners;
        for (unsigned v = 0; v < 4; ++v)
          if (pattern.zmask & (1u << v))
            corners.push_back({true, v});
        for (unsigned e = 0; e < 6; ++e)
          if (crossing & (1u << e))
            corners.push_back({false, e});
        unsigned n_planes = 0;
        for (unsigned attempt = 0; attempt < 2000 && n_planes < 24; ++attempt)
        {
          Sample s;
          if (!random_section(pattern, corners, crossing, rng, s))
            continue;
          ++n_planes;
          add_complete_sample(configurations, crossing, pattern.zmask, s);
          add_partial_samples(configurations, pattern.zmask, s, rng);
        }
        if (n_planes == 0)
          throw std::logic_error("split table: no plane realises a side pattern");
      }
    }

    // Conforming refinements through the cut points of any set of edges (no separation).
    Configuration
    refinement_configuration(const unsigned edges, std::mt19937 &rng)
    {
      const auto                             X = reference_tetrahedron();
      std::uniform_real_distribution<double> param(0.02, 0.98);
      Configuration                          cfg;
      cfg.kind  = CutKind::refinement;
      cfg.edges = static_cast<std::uint8_t>(edges);
      cfg.name  = "R" + std::to_string(popcount(edges));
      for (unsigned k = 0; k < 24; ++k)
      {
        Sample s;
        for (unsigned v = 0; v < 4; ++v)
          s.x[v] = X[v];
        for (unsigned e = 0; e < 6; ++e)
          if (edges & (1u << e))
          {
            const unsigned i = tet_edge_vertices[e][0], j = tet_edge_vertices[e][1];
            s.x[first_copy(e)] = lerp(X[i], X[j], param(rng));
          }
        cfg.samples.push_back(s);
      }
      return cfg;
    }

    // The rule, on ranks (the canonical frame's vertex indices are the ranks).
    bool
    diagonal_rule(const unsigned p0, const unsigned p1, const unsigned z)
    {
      return quad_diagonal_through_first(p0, p1, z);
    }

    // Triangulation of the boundary of the tetrahedron, face by face. Each face uses only
    // its own data, so the neighbour across it makes the same triangles.
    std::vector<PieceTriangle>
    face_triangles(const Configuration &cfg, const Sample &s, const bool copies)
    {
      const auto                 X = reference_tetrahedron();
      std::vector<PieceTriangle> result;
      for (unsigned f = 0; f < 4; ++f)
      {
        std::array<unsigned, 3> v;
        for (unsigned k = 0, n = 0; k < 4; ++k)
          if (k != f)
            v[n++] = k;
        if (signed_volume6(X[v[0]], X[v[1]], X[v[2]], X[f]) < 0)
          std::swap(v[1], v[2]); // counter-clockwise seen from inside
        std::vector<std::uint8_t> poly;
        std::vector<bool>         is_edge_point;
        for (unsigned k = 0; k < 3; ++k)
        {
          poly.push_back(static_cast<std::uint8_t>(v[k]));
          is_edge_point.push_back(false);
          const int e = tet_edge_of_vertices[v[k]][v[(k + 1) % 3]];
          if (cfg.edges & (1u << e))
          {
            poly.push_back(first_copy(static_cast<unsigned>(e)));
            is_edge_point.push_back(true);
          }
        }
        const unsigned n = static_cast<unsigned>(poly.size());
        std::vector<std::array<unsigned, 3>>
          tri; // positions in poly, or n for the face point
        if (cfg.faces & (1u << f))
          for (unsigned i = 0; i < n; ++i)
            tri.push_back({n, i, (i + 1) % n});
        else if (n == 3)
          tri.push_back({0, 1, 2});
        else if (n == 4)
        {
          unsigned i = 0;
          while (!is_edge_point[i])
            ++i;
          tri.push_back({i, (i + 1) % 4, (i + 2) % 4});
          tri.push_back({i, (i + 2) % 4, (i + 3) % 4});
        }
        else if (n == 5)
        {
          // z: the vertex between the two edge points; quad p1, x, y, p2.
          unsigned i = 0;
          while (is_edge_point[i] || !is_edge_point[(i + 1) % 5]
                 || !is_edge_point[(i + 4) % 5])
            ++i;
          const unsigned z = i, p1 = (i + 1) % 5, x = (i + 2) % 5, y = (i + 3) % 5,
                         p2 = (i + 4) % 5;
          tri.push_back({p2, z, p1});
          // Paper's quad p0=x, p1=y, a=p2 (on y-z), b=p1 (on x-z): diagonal x-p2 iff
          // x or p1 comes first.
          if (diagonal_rule(poly[x], poly[y], poly[z]))
          {
            tri.push_back({p1, x, p2});
            tri.push_back({x, y, p2});
          }
          else
          {
            tri.push_back({p1, x, y});
            tri.push_back({p1, y, p2});
          }
        }
        else
        {
          // Three cut edges: the corners and the middle triangle.
          tri.push_back({5, 0, 1});
          tri.push_back({1, 2, 3});
          tri.push_back({3, 4, 5});
          tri.push_back({1, 3, 5});
        }

        for (const auto &t : tri)
        {
          PieceTriangle out;
          Point         centroid{0, 0, 0};
          for (unsigned k = 0; k < 3; ++k)
          {
            out[k]   = t[k] == n ? face_node(f) : poly[t[k]];
            centroid = add(centroid, scale(1.0 / 3.0, s.x[out[k]]));
          }
          if (copies)
          {
            // An edge point takes the copy of the side the triangle lies on.
            const double dc = dot(s.normal, sub(centroid, s.origin));
            if (std::abs(dc) < 1e-9)
              throw std::logic_error("split table: face triangle on the cut plane");
            for (unsigned k = 0; k < 3; ++k)
              if (t[k] != n && is_edge_point[t[k]])
              {
                const unsigned e = out[k] - 4u;
                const unsigned i = tet_edge_vertices[e][0];
                out[k] = (dc > 0) == (s.d[i] > 0) ? first_copy(e) : second_copy(e);
              }
          }
          result.push_back(out);
        }
      }
      return result;
    }

    // The copy of a cut corner on the side of the sample's normal (sign > 0) or opposite.
    std::uint8_t
    corner_node(const Corner &c, const Sample &s, const int sign)
    {
      if (c.is_vertex)
        return static_cast<std::uint8_t>(c.index);
      const unsigned i = tet_edge_vertices[c.index][0];
      return (s.d[i] > 0) == (sign > 0) ? first_copy(c.index) : second_copy(c.index);
    }

    // All triangulations of a convex polygon with n corners, as index triples in
    // counter-clockwise order.
    void
    polygon_triangulations(const std::vector<unsigned>                       &poly,
                           std::vector<std::array<unsigned, 3>>              &current,
                           std::vector<std::vector<std::array<unsigned, 3>>> &all,
                           std::vector<std::vector<unsigned>>                 pending)
    {
      if (poly.size() >= 3)
        pending.push_back(poly);
      if (pending.empty())
      {
        all.push_back(current);
        return;
      }
      const std::vector<unsigned> p = pending.back();
      pending.pop_back();
      const std::size_t n = p.size();
      for (std::size_t k = 1; k + 1 < n; ++k)
      {
        current.push_back({p[0], p[k], p[n - 1]});
        auto                  next = pending;
        std::vector<unsigned> left(p.begin(), p.begin() + k + 1);
        std::vector<unsigned> right(p.begin() + k, p.end());
        if (left.size() >= 3)
          next.push_back(left);
        if (right.size() >= 3)
          next.push_back(right);
        polygon_triangulations({}, current, all, next);
        current.pop_back();
      }
    }

    std::vector<std::vector<std::array<unsigned, 3>>>
    polygon_triangulations(const unsigned n)
    {
      std::vector<unsigned> poly(n);
      for (unsigned i = 0; i < n; ++i)
        poly[i] = i;
      std::vector<std::array<unsigned, 3>>              current;
      std::vector<std::vector<std::array<unsigned, 3>>> all;
      polygon_triangulations(poly, current, all, {});
      return all;
    }

    // ---------------------------------------------------------------------------------
    // The table.

    struct TableChild
    {
      std::array<std::uint8_t, 4> nodes;
      std::uint8_t                cut_faces;
      std::uint8_t                vertex_mask; // off-cut vertices deciding the side
    };

    struct TableEntry
    {
      CutKind                     kind;
      std::uint16_t               first_child;
      std::uint8_t                n_children;
      std::uint32_t               interior_mask; // nodes averaged for the interior point
      std::array<std::uint8_t, 4> quad;          // case B: the cut quadrilateral's edges
      std::uint16_t               alternate; // case B: the entry with the other diagonal
    };

    // A vertex permutation: canonical vertex k is local vertex to_local[k].
    struct Permutation
    {
      std::array<std::uint8_t, 4>  to_local;
      bool                         odd;
      std::array<std::uint8_t, 64> edges_to_canonical;
      std::array<std::uint8_t, 16>
        vertices_to_canonical; // also faces (face f ~ vertex f)
      std::array<std::uint8_t, 16>         vertices_to_local;
      std::array<std::uint8_t, n_node_ids> node_to_local;
    };

    struct Table
    {
      std::vector<TableEntry>             entries;
      std::vector<TableChild>             children;
      std::vector<SplitTableEntry>        public_entries;
      std::array<std::uint16_t, 1u << 14> entry_of_key;
      std::array<std::uint16_t, 64>       refinement_entry;
      std::array<Permutation, 24>         permutations;
      std::array<std::uint8_t, 256>       permutation_of_ranks;
      std::array<std::uint8_t, 256> crossing_edges; // by (plus mask | minus mask << 4)
      // Decoding of local node ids.
      std::array<NodeRef, n_node_ids>      node_ref;
      std::array<std::uint8_t, n_node_ids> node_vertex; // vertex a copy sides with
    };

    constexpr std::uint16_t no_entry = 0xFFFF;

    void
    add_entry(Table                                            &table,
              const Configuration                              &cfg,
              const Key                                         key,
              const std::vector<std::vector<PieceTetrahedron>> &pieces,
              const std::vector<std::uint32_t>                 &piece_vertices,
              const std::array<std::uint32_t, 32>              &plane_mask,
              const std::uint32_t                               interior_mask,
              const std::array<std::uint8_t, 4>                &quad,
              const std::uint8_t                                variant)
    {
      TableEntry entry{};
      entry.kind          = cfg.kind;
      entry.first_child   = static_cast<std::uint16_t>(table.children.size());
      entry.interior_mask = interior_mask;
      entry.quad          = quad;
      entry.alternate     = no_entry;
      SplitTableEntry info{cfg.kind,
                           cfg.name,
                           cfg.edges,
                           cfg.vertices,
                           cfg.faces,
                           variant,
                           0,
                           interior_mask != 0,
                           {}};
      for (std::size_t p = 0; p < pieces.size(); ++p)
        for (const auto &t : pieces[p])
        {
          TableChild c{};
          for (unsigned k = 0; k < 4; ++k)
          {
            const std::uint8_t id = t[k] == steiner_node ? interior_node : t[k];
            c.nodes[k]            = id;
            if (id < 4 && !(cfg.vertices & (1u << id)))
              c.vertex_mask |= static_cast<std::uint8_t>(1u << id);
          }
          if (c.vertex_mask == 0)
            c.vertex_mask = static_cast<std::uint8_t>(piece_vertices[p]);
          for (unsigned k = 0; k < 4; ++k)
          {
            std::uint32_t m = 0xFFFFFFFFu;
            for (unsigned j = 0; j < 4; ++j)
              if (j != k)
                m &= c.nodes[j] == interior_node ? 0u : plane_mask[c.nodes[j]];
            if (m & cut_plane_bit)
              c.cut_faces |= static_cast<std::uint8_t>(1u << k);
          }
          table.children.push_back(c);
          info.children.push_back(c.nodes);
        }
      entry.n_children =
        static_cast<std::uint8_t>(table.children.size() - entry.first_child);
      if (entry.n_children > max_split_children)
        throw std::logic_error("split table: too many children in " + cfg.name);
      info.n_children = entry.n_children;
      if (key != no_entry)
        table.entry_of_key[key] = static_cast<std::uint16_t>(table.entries.size());
      table.entries.push_back(entry);
      table.public_entries.push_back(std::move(info));
    }

    // Plane membership of the canonical nodes: bit f for face f, cut_plane_bit for the
    // cut surface.
    std::array<std::uint32_t, 32>
    plane_masks(const Configuration &cfg, const bool copies)
    {
      std::array<std::uint32_t, 32> mask{};
      for (unsigned v = 0; v < 4; ++v)
        mask[v] = faces_of_vertex(v) | ((cfg.vertices & (1u << v)) ? cut_plane_bit : 0u);
      for (unsigned e = 0; e < 6; ++e)
        mask[first_copy(e)] = mask[second_copy(e)] =
          faces_of_edge(e) | (copies ? cut_plane_bit : 0u);
      for (unsigned f = 0; f < 4; ++f)
        mask[face_node(f)] = (1u << f) | cut_plane_bit;
      return mask;
    }

    /// What the entries of one configuration are built from (build_configuration()):
    /// the table they go into, the configuration and its key, the problem its pieces
    /// start from (the samples and the planes' masks) and its face triangulations.
    struct EntryBuild
    {
      Table                     &table;
      const Configuration       &cfg;
      Key                        key;
      PieceProblem               base;
      std::vector<PieceTriangle> faces;

      /// The sample the pieces are built on.
      const Sample &
      sample() const
      {
        return cfg.samples.front();
      }
    };


    /// The entry of a configuration that leaves the tetrahedron whole (none, touch).
    void
    add_whole_entry(const EntryBuild &b)
    {
      add_entry(b.table,
                b.cfg,
                b.key,
                {{PieceTetrahedron{0, 1, 2, 3}}},
                {0xFu & ~b.cfg.vertices},
                b.base.plane_mask,
                0,
                {},
                0);
    }


    /// The entry of a conforming refinement through the cut points (nothing
    /// separated).
    void
    add_refinement_entry(const EntryBuild &b)
    {
      PieceProblem problem = b.base;
      problem.boundary     = b.faces;
      for (std::uint8_t v = 0; v < 4; ++v)
        problem.nodes.push_back(v);
      for (unsigned e = 0; e < 6; ++e)
        if (b.cfg.edges & (1u << e))
          problem.nodes.push_back(first_copy(e));
      const auto    d        = decompose_piece(problem, 12);
      std::uint32_t interior = 0;
      if (d.uses_interior_node)
        for (const auto v : problem.nodes)
          interior |= 1u << v;
      add_entry(
        b.table, b.cfg, b.key, {d.tetrahedra}, {0xF}, b.base.plane_mask, interior, {}, 0);
    }


    /// The entries of a complete cut: two pieces, each decomposed; a quadrilateral
    /// section has one entry per diagonal.
    void
    add_complete_entries(const EntryBuild &b)
    {
      const unsigned n_variants = b.sample().corners.size() == 4 ? 2 : 1;
      std::uint16_t  first      = no_entry;
      for (unsigned variant = 0; variant < n_variants; ++variant)
      {
        std::vector<std::vector<PieceTetrahedron>> pieces;
        std::vector<std::uint32_t>                 piece_vertices;
        std::uint32_t                              interior = 0;
        for (const int sign : {1, -1})
        {
          PieceProblem  problem  = b.base;
          std::uint32_t vertices = 0;
          for (std::uint8_t v = 0; v < 4; ++v)
            if (b.sample().d[v] * sign > 0 || b.sample().d[v] == 0)
            {
              problem.nodes.push_back(v);
              if (b.sample().d[v] != 0)
                vertices |= 1u << v;
            }
          for (unsigned e = 0; e < 6; ++e)
            if (b.cfg.edges & (1u << e))
              problem.nodes.push_back(corner_node({false, e}, b.sample(), sign));
          const auto in_piece = [&](const std::uint8_t id)
          {
            return std::find(problem.nodes.begin(), problem.nodes.end(), id)
                   != problem.nodes.end();
          };
          for (const auto &t : b.faces)
            if (in_piece(t[0]) && in_piece(t[1]) && in_piece(t[2]))
              problem.boundary.push_back(t);
          // The cut polygon, facing this piece.
          std::vector<std::uint8_t> c;
          for (const auto &corner : b.sample().corners)
            c.push_back(corner_node(corner, b.sample(), sign));
          std::vector<std::array<unsigned, 3>> tri;
          if (c.size() == 3)
            tri = {{0, 1, 2}};
          else if (variant == 0)
            tri = {{0, 1, 2}, {0, 2, 3}};
          else
            tri = {{1, 2, 3}, {1, 3, 0}};
          for (const auto &t : tri)
            problem.boundary.push_back(sign > 0
                                         ? PieceTriangle{c[t[0]], c[t[1]], c[t[2]]}
                                         : PieceTriangle{c[t[0]], c[t[2]], c[t[1]]});
          const auto d = decompose_piece(problem, 12);
          if (d.uses_interior_node)
          {
            if (interior != 0)
              throw std::logic_error("split table: two interior points in " + b.cfg.name);
            for (const auto v : problem.nodes)
              interior |= 1u << v;
          }
          pieces.push_back(d.tetrahedra);
          piece_vertices.push_back(vertices);
        }
        std::array<std::uint8_t, 4> quad{};
        for (std::size_t k = 0; k < b.sample().corners.size() && k < 4; ++k)
          quad[k] = static_cast<std::uint8_t>(b.sample().corners[k].index);
        add_entry(b.table,
                  b.cfg,
                  variant == 0 ? b.key : no_entry,
                  pieces,
                  piece_vertices,
                  b.base.plane_mask,
                  interior,
                  quad,
                  static_cast<std::uint8_t>(variant));
        if (variant == 0)
          first = static_cast<std::uint16_t>(b.table.entries.size() - 1);
        else
          b.table.entries[first].alternate =
            static_cast<std::uint16_t>(b.table.entries.size() - 1);
      }
    }


    /// The entry of a partial cut: one piece, slit along the crack.
    void
    add_partial_entry(const EntryBuild &b)
    {
      // Partial: one piece, the tetrahedron slit along the crack polygon (the run of
      // corners and the two front points). The crack is internal, so every triangulation
      // of it is tried.
      std::vector<std::uint8_t> front;
      for (unsigned f = 0; f < 4; ++f)
        if (b.cfg.faces & (1u << f))
          front.push_back(face_node(f));
      // Order the crack polygon counter-clockwise around the normal: the run is already
      // in order; the front points follow the run's last corner.
      const Corner  &last = b.sample().corners.back();
      const unsigned last_faces =
        last.is_vertex ? faces_of_vertex(last.index) : faces_of_edge(last.index);
      std::uint8_t after = front[0], before = front[1];
      if (b.sample().corners.size() == 1)
      {
        // One corner: orient by geometry.
        const Point a = corner_position(last, b.sample());
        if (dot(b.sample().normal,
                cross(sub(b.sample().x[front[0]], a), sub(b.sample().x[front[1]], a)))
            < 0)
          std::swap(after, before);
      }
      else if (!(last_faces & (1u << (after - 16))))
        std::swap(after, before);

      PieceProblem problem = b.base;
      for (std::uint8_t v = 0; v < 4; ++v)
        problem.nodes.push_back(v);
      for (unsigned e = 0; e < 6; ++e)
        if (b.cfg.edges & (1u << e))
        {
          problem.nodes.push_back(first_copy(e));
          problem.nodes.push_back(second_copy(e));
        }
      problem.nodes.push_back(front[0]);
      problem.nodes.push_back(front[1]);

      std::vector<std::uint8_t> plus, minus;
      for (const auto &corner : b.sample().corners)
      {
        plus.push_back(corner_node(corner, b.sample(), 1));
        minus.push_back(corner_node(corner, b.sample(), -1));
      }
      plus.push_back(after);
      plus.push_back(before);
      minus.push_back(after);
      minus.push_back(before);
      // Check the crack polygon really is counter-clockwise around the normal.
      {
        Point area{0, 0, 0};
        for (std::size_t k = 0; k < plus.size(); ++k)
          area =
            add(area,
                cross(b.sample().x[plus[k]], b.sample().x[plus[(k + 1) % plus.size()]]));
        if (dot(area, b.sample().normal) <= 0)
          throw std::logic_error("split table: crack polygon orientation in "
                                 + b.cfg.name);
      }

      std::optional<std::vector<PieceTetrahedron>> best;
      for (const auto &tri : polygon_triangulations(static_cast<unsigned>(plus.size())))
      {
        PieceProblem p = problem;
        p.boundary     = b.faces;
        for (const auto &t : tri)
        {
          p.boundary.push_back({plus[t[0]], plus[t[1]], plus[t[2]]});
          p.boundary.push_back({minus[t[0]], minus[t[2]], minus[t[1]]});
        }
        const unsigned limit = best ? static_cast<unsigned>(best->size()) - 1 : 12;
        if (auto tets = minimal_tetrahedralization(p, limit))
          best = std::move(tets);
      }
      if (!best)
        throw std::logic_error("split table: no decomposition for partial case "
                               + b.cfg.name);
      add_entry(b.table,
                b.cfg,
                b.key,
                {*best},
                {0xFu & ~b.cfg.vertices},
                b.base.plane_mask,
                0,
                {},
                0);
    }


    void
    build_configuration(Table &table, const Configuration &cfg, const Key key)
    {
      const Sample &s0  = cfg.samples.front();
      const bool copies = cfg.kind == CutKind::complete || cfg.kind == CutKind::partial;
      const auto mask   = plane_masks(cfg, copies);
      const auto faces  = face_triangles(cfg, s0, copies);
      // The face rules must not depend on the sample (the table serves all of them).
      for (const auto &s : cfg.samples)
        if (face_triangles(cfg, s, copies) != faces)
          throw std::logic_error("split table: face triangulation varies in " + cfg.name);

      EntryBuild b{table, cfg, key, {}, faces};
      b.base.plane_mask = mask;
      for (const auto &s : cfg.samples)
        b.base.samples.push_back(s.x);

      switch (cfg.kind)
      {
        case CutKind::none:
        case CutKind::touch:
          add_whole_entry(b);
          break;
        case CutKind::refinement:
          add_refinement_entry(b);
          break;
        case CutKind::complete:
          add_complete_entries(b);
          break;
        default:
          add_partial_entry(b);
      }
    }

    void
    build_permutations(Table &table)
    {
      table.permutation_of_ranks.fill(0xFF);
      std::array<std::uint8_t, 4> perm{0, 1, 2, 3};
      unsigned                    index = 0;
      do
      {
        Permutation &p      = table.permutations[index];
        p.to_local          = perm;
        unsigned inversions = 0;
        for (unsigned i = 0; i < 4; ++i)
          for (unsigned j = i + 1; j < 4; ++j)
            if (perm[i] > perm[j])
              ++inversions;
        p.odd = inversions % 2 == 1;
        std::array<std::uint8_t, 4> rank;
        for (unsigned k = 0; k < 4; ++k)
          rank[perm[k]] = static_cast<std::uint8_t>(k);
        table.permutation_of_ranks[rank[0] | (rank[1] << 2) | (rank[2] << 4)
                                   | (rank[3] << 6)] = static_cast<std::uint8_t>(index);
        for (unsigned m = 0; m < 16; ++m)
        {
          unsigned c = 0, l = 0;
          for (unsigned v = 0; v < 4; ++v)
            if (m & (1u << v))
            {
              c |= 1u << rank[v];
              l |= 1u << perm[v];
            }
          p.vertices_to_canonical[m] = static_cast<std::uint8_t>(c);
          p.vertices_to_local[m]     = static_cast<std::uint8_t>(l);
        }
        for (unsigned m = 0; m < 64; ++m)
        {
          unsigned c = 0;
          for (unsigned e = 0; e < 6; ++e)
            if (m & (1u << e))
              c |= 1u << tet_edge_of_vertices[rank[tet_edge_vertices[e][0]]]
                                             [rank[tet_edge_vertices[e][1]]];
          p.edges_to_canonical[m] = static_cast<std::uint8_t>(c);
        }
        for (unsigned id = 0; id < n_node_ids; ++id)
        {
          std::uint8_t local = static_cast<std::uint8_t>(id);
          if (id < 4)
            local = perm[id];
          else if (id < 16)
          {
            const unsigned e      = (id - 4) % 6;
            const unsigned toward = tet_edge_vertices[e][id < 10 ? 0 : 1];
            const unsigned other  = tet_edge_vertices[e][id < 10 ? 1 : 0];
            const unsigned a = perm[toward], b = perm[other];
            const unsigned le = static_cast<unsigned>(tet_edge_of_vertices[a][b]);
            local             = a < b ? first_copy(le) : second_copy(le);
          }
          else if (id < 20)
            local = face_node(perm[id - 16]);
          p.node_to_local[id] = local;
        }
        ++index;
      } while (std::next_permutation(perm.begin(), perm.end()));

      for (unsigned m = 0; m < 256; ++m)
      {
        const unsigned plus = m & 0xFu, minus = m >> 4;
        unsigned       c = 0;
        for (unsigned e = 0; e < 6; ++e)
        {
          const unsigned a = 1u << tet_edge_vertices[e][0],
                         b = 1u << tet_edge_vertices[e][1];
          if (((plus & a) && (minus & b)) || ((plus & b) && (minus & a)))
            c |= 1u << e;
        }
        table.crossing_edges[m] = static_cast<std::uint8_t>(c);
      }

      for (unsigned id = 0; id < n_node_ids; ++id)
      {
        NodeRef r{};
        table.node_vertex[id] = no_vertex;
        if (id < 4)
          r = {NodeKind::vertex, static_cast<std::uint8_t>(id), 0};
        else if (id < 16)
        {
          const unsigned e = (id - 4) % 6;
          r                = {NodeKind::edge_point, static_cast<std::uint8_t>(e), 0};
          table.node_vertex[id] =
            static_cast<std::uint8_t>(tet_edge_vertices[e][id < 10 ? 0 : 1]);
        }
        else if (id < 20)
          r = {NodeKind::face_point, static_cast<std::uint8_t>(id - 16), 0};
        else
          r = {NodeKind::interior_point, 0, 0};
        table.node_ref[id] = r;
      }
    }

    Table
    build_table()
    {
      Table table;
      table.entry_of_key.fill(no_entry);
      table.refinement_entry.fill(no_entry);
      build_permutations(table);

      std::mt19937                 rng(20240917u);
      std::map<Key, Configuration> configurations;
      enumerate_sections(configurations, rng);
      for (const auto &[key, cfg] : configurations)
        build_configuration(table, cfg, key);
      for (unsigned edges = 1; edges < 64; ++edges)
      {
        build_configuration(table, refinement_configuration(edges, rng), no_entry);
        table.refinement_entry[edges] =
          static_cast<std::uint16_t>(table.entries.size() - 1);
      }
      table.refinement_entry[0] = table.entry_of_key[0];
      return table;
    }

    const Table &
    table()
    {
      static const Table instance = build_table();
      return instance;
    }

    double
    squared_distance(const Point &a, const Point &b)
    {
      return dot(sub(a, b), sub(a, b));
    }
  } // namespace


  EdgeSnap
  snap_edge_parameter(const double t, const double snap_fraction)
  {
    if (t < snap_fraction)
      return EdgeSnap::first_vertex;
    if (t > 1.0 - snap_fraction)
      return EdgeSnap::second_vertex;
    return EdgeSnap::inside;
  }


  double
  clamp_front_parameter(const double s, const double snap_fraction)
  {
    return std::min(std::max(s, snap_fraction), 1.0 - snap_fraction);
  }


  std::array<VertexId, 2>
  diagonal_order_key(const VertexId a, const VertexId b)
  {
    return {std::min(a, b), std::max(a, b)};
  }


  bool
  quad_diagonal_through_first(const VertexId p0, const VertexId p1, const VertexId z)
  {
    const auto k_p0 = diagonal_order_key(p0, p0), k_p1 = diagonal_order_key(p1, p1);
    const auto k_a = diagonal_order_key(p1, z), k_b = diagonal_order_key(p0, z);
    const auto smallest = std::min({k_p0, k_p1, k_a, k_b});
    return smallest == k_p0 || smallest == k_b;
  }


  bool
  PointKey::operator==(const PointKey &other) const
  {
    return kind == other.kind && side == other.side && ids == other.ids;
  }


  bool
  PointKey::operator<(const PointKey &other) const
  {
    return std::tie(kind, side, ids) < std::tie(other.kind, other.side, other.ids);
  }


  PointKey
  point_key(const std::array<VertexId, 4> &vertex_ids,
            const NodeRef                 &node,
            const VertexId                 parent_id)
  {
    PointKey key;
    key.kind = node.kind;
    switch (node.kind)
    {
      case NodeKind::vertex:
        key.ids = {vertex_ids[node.index], 0, 0};
        break;
      case NodeKind::edge_point:
      {
        const VertexId a = vertex_ids[tet_edge_vertices[node.index][0]],
                       b = vertex_ids[tet_edge_vertices[node.index][1]];
        key.ids          = {std::min(a, b), std::max(a, b), 0};
        key.side         = node.side;
        break;
      }
      case NodeKind::face_point:
      {
        std::array<VertexId, 3> ids;
        for (unsigned k = 0, n = 0; k < 4; ++k)
          if (k != node.index)
            ids[n++] = vertex_ids[k];
        std::sort(ids.begin(), ids.end());
        key.ids = ids;
        break;
      }
      case NodeKind::interior_point:
        key.ids = {parent_id, 0, 0};
        break;
    }
    return key;
  }


  double
  shortest_child_edge(const TetCut &cut, const SplitResult &result)
  {
    double shortest = std::numeric_limits<double>::infinity();
    for (unsigned c = 0; c < result.n_children; ++c)
    {
      std::array<Point, 4> p;
      for (unsigned k = 0; k < 4; ++k)
      {
        const NodeRef &n = result.children[c].nodes[k];
        p[k]             = n.kind == NodeKind::vertex       ? cut.points[n.index]
                           : n.kind == NodeKind::edge_point ? result.edge_points[n.index]
                           : n.kind == NodeKind::face_point ? result.face_points[n.index]
                                                            : result.interior_point;
      }
      for (unsigned i = 0; i < 4; ++i)
        for (unsigned j = i + 1; j < 4; ++j)
          shortest = std::min(shortest, squared_distance(p[i], p[j]));
    }
    return std::sqrt(shortest);
  }


  const std::vector<SplitTableEntry> &
  split_table_entries()
  {
    return table().public_entries;
  }


  namespace
  {
    /// The permutation to the canonical frame of a tetrahedron with vertex ids
    /// @p ids: canonical vertex k is the local vertex with the k-th smallest global id
    /// (every diagonal decision depends on this order only).
    inline const Permutation &
    canonical_frame(const Table &T, const std::array<VertexId, 4> &ids)
    {
      unsigned ranks = 0;
      for (unsigned i = 0; i < 4; ++i)
      {
        const unsigned r =
          (ids[0] < ids[i]) + (ids[1] < ids[i]) + (ids[2] < ids[i]) + (ids[3] < ids[i]);
        ranks |= r << (2 * i);
      }
      const unsigned perm_index = T.permutation_of_ranks[ranks];
      if (perm_index == 0xFF)
        throw std::invalid_argument("split_tetrahedron: vertex ids are not distinct");
      return T.permutations[perm_index];
    }


    /// The table entry for @p cut in frame @p P, whose vertices on the + and - sides
    /// and on the cut are @p plus, @p minus and @p on_cut: the entry of its cut edges,
    /// vertices on the cut and front faces if they describe a cut that the sides
    /// allow, else the refinement through its cut edges; no_entry if front faces do
    /// not describe a partial cut.
    inline std::uint16_t
    find_entry(const Table       &T,
               const Permutation &P,
               const TetCut      &cut,
               const unsigned     plus,
               const unsigned     minus,
               const unsigned     on_cut)
    {
      const unsigned crossing = T.crossing_edges[plus | (minus << 4)];
      const unsigned edges    = cut.cut_edges & 0x3Fu;
      const unsigned key =
        P.edges_to_canonical[edges]
        | (static_cast<unsigned>(P.vertices_to_canonical[on_cut]) << 6)
        | (static_cast<unsigned>(P.vertices_to_canonical[cut.front_faces & 0xFu]) << 10);
      const std::uint16_t index = T.entry_of_key[key];
      bool                valid = index != no_entry;
      if (valid)
      {
        switch (T.entries[index].kind)
        {
          case CutKind::complete:
            valid = crossing == edges;
            break;
          case CutKind::partial:
            valid = (edges & ~crossing) == 0;
            break;
          case CutKind::touch:
            valid = crossing == 0 && edges == 0;
            break;
          default:
            break;
        }
      }
      if (valid)
        return index;
      if (cut.front_faces != 0)
        return no_entry;
      return T.refinement_entry[P.edges_to_canonical[edges]];
    }


    /// The new points' positions: cut points clamped to [ε, 1 - ε] from the endpoint
    /// with the smaller id (so that neighbours sharing the edge get bit-identical
    /// points), and the front points.
    inline void
    place_new_points(const TetCut &cut, const double eps, SplitResult &result)
    {
      const auto    &ids   = cut.vertex_ids;
      const unsigned edges = cut.cut_edges & 0x3Fu;
      for (unsigned e = 0; e < 6; ++e)
        if (edges & (1u << e))
        {
          unsigned a = tet_edge_vertices[e][0], b = tet_edge_vertices[e][1];
          if (ids[b] < ids[a])
            std::swap(a, b);
          const double t = std::min(std::max(cut.edge_parameter[e], eps), 1.0 - eps);
          for (unsigned k = 0; k < 3; ++k)
            result.edge_points[e][k] =
              cut.points[a][k] + t * (cut.points[b][k] - cut.points[a][k]);
        }
      for (unsigned f = 0; f < 4; ++f)
        if (cut.front_faces & (1u << f))
          result.face_points[f] = cut.front_points[f];
    }


    /// Entry @p index, or for case B its alternate when that has the longer diagonal:
    /// the cut quadrilateral is internal to the tetrahedron, so its diagonal may be
    /// chosen by geometry. The diagonal is the only edge the two choices do not share,
    /// and short edges limit the stable time step. (In a sliver two opposite corners
    /// can almost coincide.)
    inline std::uint16_t
    choose_diagonal(const Table        &T,
                    const Permutation  &P,
                    const std::uint16_t index,
                    const SplitResult  &result)
    {
      const TableEntry &entry = T.entries[index];
      if (entry.alternate == no_entry)
        return index;
      std::array<Point, 4> q;
      for (unsigned k = 0; k < 4; ++k)
      {
        const unsigned local = P.node_to_local[first_copy(entry.quad[k])];
        q[k]                 = result.edge_points[(local - 4) % 6];
      }
      return squared_distance(q[1], q[3]) > squared_distance(q[0], q[2]) ? entry.alternate
                                                                         : index;
    }


    /// The children of @p entry in the local frame of @p cut (through @p P), with the
    /// sides of their nodes and of themselves, positively oriented (@p flip: the
    /// parent's orientation reverses the table's).
    inline void
    emit_children(const Table       &T,
                  const Permutation &P,
                  const TableEntry  &entry,
                  const TetCut      &cut,
                  const unsigned     plus,
                  const unsigned     minus,
                  const bool         flip,
                  SplitResult       &result)
    {
      const bool separates =
        entry.kind == CutKind::complete || entry.kind == CutKind::partial;
      // The side every local node id takes, without branching per node: a separated
      // edge point takes the side of the endpoint its copy belongs to; a vertex on the
      // cut takes the side of its child (multiplier 1); everything else 0.
      std::array<std::int8_t, n_node_ids> base{}, on_cut_multiplier{};
      if (separates)
      {
        for (unsigned id = 4; id < 16; ++id)
          base[id] = cut.vertex_side[T.node_vertex[id]];
        for (unsigned v = 0; v < 4; ++v)
          on_cut_multiplier[v] = cut.vertex_side[v] == 0;
      }
      const TableChild *tc = &T.children[entry.first_child];
      for (unsigned c = 0; c < entry.n_children; ++c, ++tc)
      {
        Child &out = result.children[c];
        // The child's side from its vertices off the cut (0 if they disagree: only
        // ahead of a crack front). A child using a separated copy has all of them on
        // the copy's side.
        const unsigned m    = P.vertices_to_local[tc->vertex_mask];
        const int      side = int((m & plus) != 0) - int((m & minus) != 0);
        out.side            = static_cast<std::int8_t>(side);
        out.cut_faces       = tc->cut_faces;
        for (unsigned k = 0; k < 4; ++k)
        {
          const std::uint8_t local = P.node_to_local[tc->nodes[k]];
          NodeRef            r     = T.node_ref[local];
          r.side =
            static_cast<std::int8_t>(base[local] + on_cut_multiplier[local] * side);
          out.nodes[k] = r;
        }
        if (flip)
        {
          std::swap(out.nodes[0], out.nodes[1]);
          out.cut_faces =
            static_cast<std::uint8_t>((out.cut_faces & 0xCu) | ((out.cut_faces & 1u) << 1)
                                      | ((out.cut_faces & 2u) >> 1));
        }
      }
    }


    /// The interior point of @p entry, if its children use one: the centroid of its
    /// piece's nodes.
    inline void
    place_interior_point(const Permutation &P,
                         const TableEntry  &entry,
                         const TetCut      &cut,
                         SplitResult       &result)
    {
      if (entry.interior_mask == 0)
        return;
      Point    c{0, 0, 0};
      unsigned n = 0;
      for (unsigned id = 0; id < n_node_ids; ++id)
        if (entry.interior_mask & (1u << id))
        {
          const std::uint8_t local = P.node_to_local[id];
          const Point       &p     = local < 4    ? cut.points[local]
                                     : local < 16 ? result.edge_points[(local - 4) % 6]
                                                  : result.face_points[local - 16];
          c                        = add(c, p);
          ++n;
        }
      result.interior_point = scale(1.0 / n, c);
    }
  } // namespace


  CutKind
  split_tetrahedron(const TetCut &cut, SplitResult &result, const double snap_fraction)
  {
    if (!(snap_fraction > 0 && snap_fraction < 0.5))
      throw std::invalid_argument(
        "split_tetrahedron: the snap fraction must lie in (0, 0.5)");
    const Table       &T    = table();
    const Permutation &P    = canonical_frame(T, cut.vertex_ids);
    unsigned           plus = 0, minus = 0, on_cut = 0;
    for (unsigned v = 0; v < 4; ++v)
    {
      const int s = cut.vertex_side[v];
      (s > 0 ? plus : (s < 0 ? minus : on_cut)) |= 1u << v;
    }
    std::uint16_t index = find_entry(T, P, cut, plus, minus, on_cut);
    if (index == no_entry)
    {
      result.kind       = CutKind::unsupported;
      result.n_children = 0;
      return result.kind;
    }
    place_new_points(cut, snap_fraction, result);
    index                   = choose_diagonal(T, P, index, result);
    const TableEntry &entry = T.entries[index];
    const double      volume6 =
      signed_volume6(cut.points[0], cut.points[1], cut.points[2], cut.points[3]);
    result.kind       = entry.kind;
    result.entry      = index;
    result.n_children = entry.n_children;
    emit_children(T, P, entry, cut, plus, minus, (volume6 < 0) != P.odd, result);
    place_interior_point(P, entry, cut, result);
    return result.kind;
  }
} // namespace lacerta::cut
