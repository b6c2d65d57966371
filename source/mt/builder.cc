#include <lacerta/base/exceptions.h>
#include <lacerta/mesh/point.h>
#include <lacerta/mt/builder.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <queue>
#include <unordered_map>

namespace lacerta::mt
{
  namespace
  {
    using mesh::add;
    using mesh::cross;
    using mesh::distance;
    using mesh::dot;
    using mesh::norm;
    using mesh::Point3;
    using mesh::point_triangle_distance;
    using mesh::scale;
    using mesh::sub;
    using mesh::Tet;
    constexpr std::uint32_t none = mesh::invalid_index;

    /// Unit normal of (a, b, c); zero if degenerate.
    Point3
    unit_normal(const Point3 &a, const Point3 &b, const Point3 &c)
    {
      Point3       n      = cross(sub(b, a), sub(c, a));
      const double length = norm(n);
      if (length > 0)
        for (double &x : n)
          x /= length;
      return n;
    }

    /// Key of a set of up to three ids below 2^21 (order-independent).
    std::uint64_t
    key3(std::uint32_t a, std::uint32_t b, std::uint32_t c)
    {
      if (a > b)
        std::swap(a, b);
      if (b > c)
        std::swap(b, c);
      if (a > b)
        std::swap(a, b);
      return (std::uint64_t(a) << 42) | (std::uint64_t(b) << 21) | c;
    }

    std::uint64_t
    key2(std::uint32_t a, std::uint32_t b)
    {
      return a < b ? (std::uint64_t(a) << 32) | b : (std::uint64_t(b) << 32) | a;
    }

    /// Sorts and removes repeated entries.
    template <typename T>
    void
    sort_unique(std::vector<T> &list)
    {
      std::sort(list.begin(), list.end());
      list.erase(std::unique(list.begin(), list.end()), list.end());
    }

    /// Whether the short list @p list holds @p key (lists of a few entries: a linear
    /// scan beats sorting or hashing them).
    bool
    holds(const std::vector<std::uint64_t> &list, const std::uint64_t key)
    {
      return std::find(list.begin(), list.end(), key) != list.end();
    }

    /// A candidate collapse of a vertex.
    struct Collapse
    {
      std::uint32_t target   = none;
      double        priority = std::numeric_limits<double>::infinity();
      double        error    = 0;
    };

    /**
     * The decimation: a mesh that loses one vertex at a time, with the record of every
     * collapse.
     */
    class Decimator
    {
    public:
      Decimator(const mesh::TetMesh             &mesh,
                const BuilderParameters         &parameters,
                const std::vector<unsigned int> &locked_vertices)
          : parameters(parameters)
          , position(mesh.get_vertices())
          , tets(mesh.get_tets())
          , alive(tets.size(), 1)
          , star(position.size())
          , removed(position.size(), 0)
          , locked(position.size(), 0)
          , boundary(position.size(), 0)
          , stamp(position.size(), 0)
          , ghost(static_cast<std::uint32_t>(position.size()))
      {
        if (position.size() + 1 >= (std::size_t(1) << 21))
          throw_error("Multiresolution: the mesh '",
                      mesh.source(),
                      "' has ",
                      position.size(),
                      " vertices; the builder handles fewer than 2^21.");
        mark.assign(position.size() + 1, 0);
        known_errors.resize(position.size());
        for (std::uint32_t t = 0; t < tets.size(); ++t)
          for (const unsigned int v : tets[t])
            star[v].push_back(t);
        for (const unsigned int v : locked_vertices)
          locked.at(v) = 1;
        Point3 low = position.empty() ? Point3{} : position[0], high = low;
        for (std::uint32_t v = 0; v < position.size(); ++v)
        {
          boundary[v] = mesh.is_boundary_vertex(v);
          for (unsigned int d = 0; d < 3; ++d)
          {
            low[d]  = std::min(low[d], position[v][d]);
            high[d] = std::max(high[d], position[v][d]);
          }
        }
        max_distance = parameters.maximum_boundary_error * distance(low, high);
        // Every input boundary vertex is a sample of the input boundary; it starts on the
        // faces around it (the first one is enough: its distance is zero).
        for (const auto &face : mesh.get_boundary_faces())
        {
          const Tet  &t = tets[face.tet];
          const auto &l = mesh::TetMesh::face_vertices[face.face];
          face_points[key3(t[l[0]], t[l[1]], t[l[2]])];
        }
      }

      void
      run()
      {
        for (std::uint32_t v = 0; v < position.size(); ++v)
          schedule(v);
        while (!queue.empty())
        {
          const Entry entry = queue.top();
          queue.pop();
          const std::uint32_t v = entry.vertex;
          if (removed[v] || entry.stamp != stamp[v])
            continue;
          if (!entry.exact)
          {
            make_exact(entry);
            continue;
          }
          const Collapse best = find_collapse(v, true);
          if (best.target == none)
            continue;
          if (best.priority > entry.priority * (1 + 1e-12))
          {
            // Compared with the next live entry, made exact: a stale one says nothing
            // about the mesh as it is, a lower bound too little.
            settle_top();
            if (!queue.empty() && best.priority > queue.top().priority)
            {
              queue.push({best.priority, v, ++stamp[v], true});
              continue;
            }
          }
          collapse(v, best.target);
        }
      }

      MultiTriangulation
      assemble() const;

    private:
      /**
       * A queue entry: the priority of a vertex when its neighbourhood had the given
       * stamp, exact or (for a boundary vertex not evaluated yet) a lower bound.
       */
      struct Entry
      {
        double        priority;
        std::uint32_t vertex;
        std::uint32_t stamp;
        bool          exact;
        bool
        operator<(const Entry &other) const
        {
          // std::priority_queue pops the largest: the smallest priority must compare
          // largest.
          return priority > other.priority
                 || (priority == other.priority && vertex > other.vertex);
        }
      };

      /**
       * Replaces the lower bound @p entry (just popped) by the exact priority, or by
       * nothing if its vertex has no valid collapse. The vertex's neighbourhood is the
       * one it was queued with, so the order in which exact entries leave the queue
       * is that of a queue of exact priorities; only the boundary vertices that reach
       * the top before their neighbourhood changes pay for the Hausdorff test.
       */
      void
      make_exact(const Entry &entry)
      {
        const Collapse c = find_collapse(entry.vertex, false);
        if (c.target != none)
          queue.push({c.priority, entry.vertex, entry.stamp, true});
      }

      /// Pops the stale entries at the top of the queue and makes the lower bounds
      /// there exact, until the top is a live exact entry (or the queue is empty).
      void
      settle_top()
      {
        while (!queue.empty())
        {
          const Entry top = queue.top();
          if (!removed[top.vertex] && top.stamp == stamp[top.vertex] && top.exact)
            return;
          queue.pop();
          if (!removed[top.vertex] && top.stamp == stamp[top.vertex])
            make_exact(top);
        }
      }

      /**
       * Outward oriented boundary faces around @p v, from its star, in @p result
       * (sorted by key3, an order the sample assignment of collapse() depends on). An
       * interior vertex has none and never gets any (a new boundary face would come from
       * an old one through v), so it costs nothing.
       */
      void
      boundary_faces(const std::uint32_t                        v,
                     std::vector<std::array<std::uint32_t, 3>> &result) const
      {
        result.clear();
        if (!boundary[v])
          return;
        auto &faces = face_scratch;
        faces.clear();
        for (const std::uint32_t t : star[v])
          for (unsigned int f = 0; f < 4; ++f)
            if (tets[t][f] != v)
            {
              const auto                        &l    = mesh::TetMesh::face_vertices[f];
              const std::array<std::uint32_t, 3> face = {
                {tets[t][l[0]], tets[t][l[1]], tets[t][l[2]]}};
              faces.push_back({key3(face[0], face[1], face[2]), face});
            }
        std::sort(faces.begin(),
                  faces.end(),
                  [](const auto &a, const auto &b) { return a.first < b.first; });
        for (std::size_t i = 0; i < faces.size();)
        {
          std::size_t j = i;
          while (j < faces.size() && faces[j].first == faces[i].first)
            ++j;
          if (j - i == 1)
            result.push_back(faces[i].second);
          i = j;
        }
      }

      /**
       * Tet @p t after collapsing @p v onto @p w, in @p result; false if t contains
       * the edge vw and disappears.
       */
      bool
      collapsed(const std::uint32_t t,
                const std::uint32_t v,
                const std::uint32_t w,
                Tet                &result) const
      {
        result = tets[t];
        if (std::find(result.begin(), result.end(), w) != result.end())
          return false;
        std::replace(result.begin(),
                     result.end(),
                     static_cast<unsigned int>(v),
                     static_cast<unsigned int>(w));
        return true;
      }

      /// A fresh value for mark[]: no entry holds it yet.
      std::uint32_t
      new_mark() const
      {
        if (++mark_value == 0)
        {
          std::fill(mark.begin(), mark.end(), 0);
          mark_value = 1;
        }
        return mark_value;
      }

      /// The vertices sharing a tetrahedron with @p v, sorted (the candidates are
      /// tried in this order, which breaks ties), in @p list.
      void
      neighbours(const std::uint32_t v, std::vector<std::uint32_t> &list) const
      {
        list.clear();
        const std::uint32_t seen = new_mark();
        mark[v]                  = seen;
        for (const std::uint32_t t : star[v])
          for (const unsigned int u : tets[t])
            if (mark[u] != seen)
            {
              mark[u] = seen;
              list.push_back(u);
            }
        std::sort(list.begin(), list.end());
      }

      /**
       * The cells around @p u in the mesh closed by the ghost vertex, in @p cells;
       * @p faces are u's boundary faces.
       */
      void
      closed_star(const std::uint32_t                              u,
                  const std::vector<std::array<std::uint32_t, 3>> &faces,
                  std::vector<std::array<std::uint32_t, 4>>       &cells) const
      {
        cells.clear();
        for (const std::uint32_t t : star[u])
          cells.push_back(tets[t]);
        for (const auto &f : faces)
          cells.push_back({{ghost, f[0], f[1], f[2]}});
      }

      /**
       * The link condition Lk(v) ∩ Lk(w) = Lk(vw) on the mesh closed by a ghost vertex
       * joined to every boundary face: it keeps the mesh a manifold and the boundary's
       * topology unchanged.
       *
       * Lk(vw) is always part of both links, so the condition is on the common
       * simplices only. It is checked with marks, without building or sorting the
       * links (this test runs for every candidate that passes the quality test):
       * common vertices = the ring of vertices around edge vw; then every common edge
       * or triangle has its vertices in that ring, a handful, so those are compared in
       * short lists. @p faces_of_v are v's boundary faces (the caller has them).
       */
      bool
      link_condition(const std::uint32_t                              v,
                     const std::vector<std::array<std::uint32_t, 3>> &faces_of_v,
                     const std::uint32_t                              w) const
      {
        closed_star(v, faces_of_v, cells_v);
        boundary_faces(w, ghost_faces);
        closed_star(w, ghost_faces, cells_w);
        // Vertices: mark Lk(v), promote those also in Lk(w) (common), then those of
        // Lk(vw) (ring); the condition holds when every common vertex is in the ring
        // and every ring vertex is common.
        const std::uint32_t in_v = new_mark(), common = new_mark(), ring = new_mark();
        for (const auto &c : cells_v)
          for (const std::uint32_t x : c)
            if (x != v)
              mark[x] = in_v;
        unsigned int n_common = 0, n_ring = 0;
        for (const auto &c : cells_w)
          for (const std::uint32_t x : c)
            if (x != w && mark[x] == in_v)
            {
              mark[x] = common;
              ++n_common;
            }
        edges_vw.clear();
        for (const auto &c : cells_v)
          if (std::find(c.begin(), c.end(), w) != c.end())
          {
            std::array<std::uint32_t, 2> o{};
            unsigned int                 n = 0;
            for (const std::uint32_t x : c)
              if (x != v && x != w)
                o[n++] = x;
            for (const std::uint32_t x : o)
              if (mark[x] == common)
              {
                mark[x] = ring;
                ++n_ring;
              }
              else if (mark[x] != ring)
                return false;
            edges_vw.push_back(key2(o[0], o[1]));
          }
        if (n_common != n_ring)
          return false;
        // Edges and triangles of each link with all their vertices in the ring: the
        // only ones that can be common.
        const auto ring_parts =
          [&](const std::vector<std::array<std::uint32_t, 4>> &cells,
              const std::uint32_t                              u,
              std::vector<std::uint64_t>                      &edges,
              std::vector<std::uint64_t>                      &triangles)
        {
          edges.clear();
          triangles.clear();
          for (const auto &c : cells)
          {
            std::array<std::uint32_t, 3> o{};
            unsigned int                 n = 0;
            for (const std::uint32_t x : c)
              if (x != u)
                o[n++] = x;
            if (n != 3)
              continue;
            unsigned int n_in = 0;
            for (unsigned int i = 0; i < 3; ++i)
              if (mark[o[i]] == ring)
              {
                ++n_in;
                if (mark[o[(i + 1) % 3]] == ring)
                  edges.push_back(key2(o[i], o[(i + 1) % 3]));
              }
            if (n_in == 3)
              triangles.push_back(key3(o[0], o[1], o[2]));
          }
        };
        ring_parts(cells_v, v, edges_v, triangles_v);
        ring_parts(cells_w, w, edges_w, triangles_w);
        // Common edges = Lk(vw)'s edges; no common triangle (Lk(vw) has none).
        for (const std::uint64_t e : edges_vw)
          if (!holds(edges_v, e) || !holds(edges_w, e))
            return false;
        for (const std::uint64_t e : edges_v)
          if (holds(edges_w, e) && !holds(edges_vw, e))
            return false;
        for (const std::uint64_t t : triangles_v)
          if (holds(triangles_w, t))
            return false;
        return true;
      }

      /**
       * Prepares boundary_error() for vertex @p v, whose boundary faces are
       * @p faces: their normals and samples do not depend on the candidate target.
       */
      void
      prepare_boundary_error(const std::vector<std::array<std::uint32_t, 3>> &faces) const
      {
        face_normals.clear();
        face_samples.clear();
        for (const auto &f : faces)
        {
          face_normals.push_back(
            unit_normal(position[f[0]], position[f[1]], position[f[2]]));
          const auto found = face_points.find(key3(f[0], f[1], f[2]));
          face_samples.push_back(found != face_points.end() ? &found->second : nullptr);
        }
      }

      /**
       * Largest distance from the input boundary samples around @p v to the boundary
       * after collapsing v onto @p w; infinite if a face would turn over or the
       * distance exceeds @p give_up (then the exact value does not matter).
       * @p faces are v's boundary faces, given to prepare_boundary_error() before.
       * @p forbidden tells an infinite result that holds whatever @p give_up.
       */
      double
      boundary_error(const std::uint32_t                              v,
                     const std::uint32_t                              w,
                     const std::vector<std::array<std::uint32_t, 3>> &faces,
                     const double                                     give_up,
                     bool                                            &forbidden) const
      {
        forbidden   = true;
        auto &after = moved_faces;
        after.clear();
        // Per face of v, its moved face in after (none: it disappears).
        moved_index.assign(faces.size(), none);
        for (std::size_t i = 0; i < faces.size(); ++i)
        {
          const auto &f = faces[i];
          if (std::find(f.begin(), f.end(), w) == f.end())
          {
            std::array<Point3, 3> moved;
            for (unsigned int k = 0; k < 3; ++k)
              moved[k] = position[f[k] == v ? w : f[k]];
            const Point3 new_normal = unit_normal(moved[0], moved[1], moved[2]);
            if (dot(face_normals[i], new_normal) < 0.5)
              return std::numeric_limits<double>::infinity();
            moved_index[i] = static_cast<std::uint32_t>(after.size());
            after.push_back(moved);
          }
        }
        if (after.empty())
          return std::numeric_limits<double>::infinity();
        forbidden = false;
        // The distance of a sample only matters if it raises the maximum so far: the
        // search over faces stops at the first face closer than that. A sample is
        // usually nearest to the moved version of the face it is attached to, so that
        // face is tried first; the minimum, hence the result, does not depend on the
        // order.
        double     error   = 0;
        const auto include = [&](const Point3 &p, const std::uint32_t first)
        {
          double d = std::numeric_limits<double>::infinity();
          if (first != none)
          {
            const auto &f = after[first];
            if ((d = point_triangle_distance(p, f[0], f[1], f[2])) <= error)
              return true;
          }
          for (const auto &f : after)
            if ((d = std::min(d, point_triangle_distance(p, f[0], f[1], f[2]))) <= error)
              return true;
          error = d;
          return error <= give_up;
        };
        if (!include(position[v], none))
          return std::numeric_limits<double>::infinity();
        for (std::size_t i = 0; i < faces.size(); ++i)
          if (face_samples[i] != nullptr)
            for (const std::uint32_t p : *face_samples[i])
              if (!include(position[p], moved_index[i]))
                return std::numeric_limits<double>::infinity();
        return error;
      }

      /**
       * boundary_error(), from what an earlier evaluation of @p v in the same
       * neighbourhood found out about @p w when that is enough: the exact error, or
       * that it exceeds a bound at least @p give_up. A vertex is evaluated when it
       * reaches the top of the queue and again in full when its exact entry does; the
       * second time costs no distance.
       */
      double
      known_boundary_error(const std::uint32_t                              v,
                           const std::uint32_t                              w,
                           const std::vector<std::array<std::uint32_t, 3>> &faces,
                           const double                                     give_up) const
      {
        auto &known = known_errors[v];
        auto  found = std::find_if(known.begin(),
                                  known.end(),
                                  [w](const KnownError &k) { return k.target == w; });
        if (found != known.end())
        {
          if (std::isfinite(found->error))
            return found->error <= give_up ? found->error
                                           : std::numeric_limits<double>::infinity();
          if (give_up <= found->above)
            return std::numeric_limits<double>::infinity();
        }
        bool             forbidden = false;
        const double     error     = boundary_error(v, w, faces, give_up, forbidden);
        const KnownError k         = {
                  w, error, forbidden ? std::numeric_limits<double>::infinity() : give_up};
        if (found != known.end())
          *found = k;
        else
          known.push_back(k);
        return error;
      }

      /**
       * The best valid collapse of @p v and its priority. With @p full, every check is
       * made; without, only the boundary error (for the priority of a queue entry).
       */
      Collapse
      find_collapse(const std::uint32_t v, const bool full) const
      {
        Collapse best;
        if (locked[v] || removed[v] || star[v].empty())
          return best;
        const double volume = mean_volume(v);
        // The priority of an interior vertex is its volume whatever the target: a queue
        // entry needs no candidate list.
        if (!boundary[v] && !full)
        {
          const Tet &t = tets[star[v][0]];
          best         = {t[0] != v ? t[0] : t[1], volume, 0};
          return best;
        }
        auto &around = around_scratch;
        neighbours(v, around);
        double mean_edge = 0;
        for (const std::uint32_t u : around)
          mean_edge += distance(position[u], position[v]);
        mean_edge /= around.size();

        auto &faces = faces_v;
        boundary_faces(v, faces);
        prepare_boundary_error(faces);
        double best_quality = -1;
        for (const std::uint32_t w : around)
        {
          double error = 0;
          if (boundary[v])
          {
            // A boundary vertex may only slide along a boundary edge onto a boundary
            // vertex.
            const bool on_boundary_edge =
              std::any_of(faces.begin(),
                          faces.end(),
                          [w](const auto &f)
                          { return std::find(f.begin(), f.end(), w) != f.end(); });
            if (!on_boundary_edge)
              continue;
            // A candidate worse than the best so far need not be measured exactly.
            const double worst = std::isfinite(best.priority)
                                   ? std::min(max_distance, best.error)
                                   : max_distance;
            error              = known_boundary_error(v, w, faces, worst);
            if (!(error <= max_distance))
              continue;
          }
          const double priority =
            boundary[v]
              ? volume * (1 + parameters.boundary_error_weight * error / mean_edge)
              : volume;
          if (priority > best.priority)
            continue;
          if (!full)
          {
            best = {w, priority, error};
            continue;
          }
          // A collapse that creates no tetrahedron (every tet of v holds w) would delete
          // a cap of the object and leave a node the DAG cannot reach: rejected.
          double       quality   = std::numeric_limits<double>::infinity();
          unsigned int n_created = 0;
          for (const std::uint32_t t : star[v])
          {
            Tet c;
            if (!collapsed(t, v, w, c))
              continue;
            ++n_created;
            quality = std::min(quality,
                               tet_quality(position[c[0]],
                                           position[c[1]],
                                           position[c[2]],
                                           position[c[3]]));
            if (quality < parameters.minimum_quality)
              break;
          }
          if (quality < parameters.minimum_quality || n_created == 0)
            continue;
          if (priority == best.priority && quality <= best_quality)
            continue;
          if (!link_condition(v, faces, w))
            continue;
          best         = {w, priority, error};
          best_quality = quality;
        }
        return best;
      }

      /// Mean volume of the tetrahedra around @p v.
      double
      mean_volume(const std::uint32_t v) const
      {
        double volume = 0;
        for (const std::uint32_t t : star[v])
          volume += mesh::signed_volume(position[tets[t][0]],
                                        position[tets[t][1]],
                                        position[tets[t][2]],
                                        position[tets[t][3]]);
        return volume / star[v].size();
      }

      /**
       * Queues @p v after its neighbourhood changed. A boundary vertex goes in with
       * the lower bound of its priority (its mean volume: the boundary error only
       * raises it), made exact if it reaches the top of the queue before it changes
       * again (most are queued many times over before that).
       */
      void
      schedule(const std::uint32_t v)
      {
        ++stamp[v];
        known_errors[v].clear();
        if (locked[v] || removed[v] || star[v].empty())
          return;
        if (boundary[v])
        {
          queue.push({mean_volume(v), v, stamp[v], false});
          return;
        }
        const Collapse c = find_collapse(v, false);
        if (c.target != none)
          queue.push({c.priority, v, stamp[v], true});
      }

      void
      collapse(const std::uint32_t v, const std::uint32_t w)
      {
        if (boundary[v])
        {
          // The samples around v go to their nearest face of the new boundary.
          std::vector<std::array<std::uint32_t, 3>> faces;
          boundary_faces(v, faces);
          std::vector<std::uint32_t> samples;
          if (v < n_input_samples())
            samples.push_back(v);
          std::vector<std::array<std::uint32_t, 3>> after;
          for (const auto &f : faces)
          {
            const auto found = face_points.find(key3(f[0], f[1], f[2]));
            if (found != face_points.end())
            {
              samples.insert(samples.end(), found->second.begin(), found->second.end());
              face_points.erase(found);
            }
            if (std::find(f.begin(), f.end(), w) == f.end())
            {
              std::array<std::uint32_t, 3> g = f;
              std::replace(g.begin(), g.end(), v, w);
              after.push_back(g);
              face_points[key3(g[0], g[1], g[2])];
            }
          }
          for (const std::uint32_t p : samples)
          {
            double      nearest = std::numeric_limits<double>::infinity();
            std::size_t which   = 0;
            for (std::size_t i = 0; i < after.size(); ++i)
            {
              const double d = point_triangle_distance(position[p],
                                                       position[after[i][0]],
                                                       position[after[i][1]],
                                                       position[after[i][2]]);
              if (d < nearest)
              {
                nearest = d;
                which   = i;
              }
            }
            face_points[key3(after[which][0], after[which][1], after[which][2])]
              .push_back(p);
          }
        }

        const std::vector<std::uint32_t> old_star = star[v];
        std::vector<std::uint32_t>       affected;
        removed_begin.push_back(static_cast<std::uint32_t>(removed_list.size()));
        created_begin.push_back(static_cast<std::uint32_t>(created_list.size()));
        for (const std::uint32_t t : old_star)
        {
          alive[t] = 0;
          removed_list.push_back(t);
          for (const unsigned int u : tets[t])
            if (u != v)
            {
              auto &s = star[u];
              s.erase(std::find(s.begin(), s.end(), t));
              affected.push_back(u);
            }
        }
        for (const std::uint32_t t : old_star)
        {
          Tet c;
          if (!collapsed(t, v, w, c))
            continue;
          const std::uint32_t id = static_cast<std::uint32_t>(tets.size());
          tets.push_back(c);
          alive.push_back(1);
          created_list.push_back(id);
          for (const unsigned int u : c)
            star[u].push_back(id);
        }
        star[v].clear();
        removed[v] = 1;
        removed_vertex.push_back(v);
        sort_unique(affected);
        for (const std::uint32_t u : affected)
          if (!removed[u])
            schedule(u);
      }

      std::uint32_t
      n_input_samples() const
      {
        return ghost;
      }

      const BuilderParameters                &parameters;
      std::vector<Point3>                     position;
      std::vector<Tet>                        tets;
      std::vector<std::uint8_t>               alive;
      std::vector<std::vector<std::uint32_t>> star;
      std::vector<std::uint8_t>               removed, locked, boundary;
      std::vector<std::uint32_t>              stamp;
      std::uint32_t                           ghost;
      double                                  max_distance = 0;
      std::unordered_map<std::uint64_t, std::vector<std::uint32_t>> face_points;
      /// What boundary_error() found for a target: the exact error, or (infinite
      /// error) that it exceeds @p above (infinite: the collapse is never allowed).
      struct KnownError
      {
        std::uint32_t target;
        double        error;
        double        above;
      };
      // Per vertex, valid until its neighbourhood changes (schedule() clears it).
      mutable std::vector<std::vector<KnownError>> known_errors;
      // Scratch of the candidate evaluation, reused so that the search allocates
      // nothing once the buffers have grown (mutable: the evaluation is logically const).
      mutable std::vector<std::uint32_t> mark;
      mutable std::uint32_t              mark_value = 0;
      mutable std::vector<std::pair<std::uint64_t, std::array<std::uint32_t, 3>>>
                                                        face_scratch;
      mutable std::vector<std::array<std::uint32_t, 3>> faces_v, ghost_faces;
      mutable std::vector<std::array<std::uint32_t, 4>> cells_v, cells_w;
      mutable std::vector<std::uint64_t> edges_vw, edges_v, edges_w, triangles_v,
        triangles_w;
      mutable std::vector<std::uint32_t>                      around_scratch;
      mutable std::vector<std::array<Point3, 3>>              moved_faces;
      mutable std::vector<std::uint32_t>                      moved_index;
      mutable std::vector<Point3>                             face_normals;
      mutable std::vector<const std::vector<std::uint32_t> *> face_samples;
      std::priority_queue<Entry>                              queue;
      // The record: collapse k removed vertex removed_vertex[k], removed the tets from
      // removed_begin[k] and created those from created_begin[k].
      std::vector<std::uint32_t> removed_vertex, removed_begin, removed_list,
        created_begin, created_list;
    };


    MultiTriangulation
    Decimator::assemble() const
    {
      const std::uint32_t K       = static_cast<std::uint32_t>(removed_vertex.size());
      const std::uint32_t n_nodes = K + 1;
      const auto          range   = [&](const std::vector<std::uint32_t> &begin,
                             const std::vector<std::uint32_t> &list,
                             const std::uint32_t               k)
      {
        const std::uint32_t first = begin[k];
        const std::uint32_t last =
          k + 1 < K ? begin[k + 1] : static_cast<std::uint32_t>(list.size());
        return std::make_pair(list.begin() + first, list.begin() + last);
      };
      // Node of collapse k: K - k, so that parents (later collapses) come first.
      std::vector<std::uint32_t> creator(tets.size(), 0), destroyer(tets.size(), none);
      for (std::uint32_t k = 0; k < K; ++k)
      {
        for (auto [i, end] = range(removed_begin, removed_list, k); i != end; ++i)
          creator[*i] = K - k;
        for (auto [i, end] = range(created_begin, created_list, k); i != end; ++i)
          destroyer[*i] = K - k;
      }
      // Tets of dead ends never happen: every tet is alive at the end or removed once.
      MultiTriangulation mt;
      mt.vertices = position;
      mt.fine_begin.assign(n_nodes + 1, 0);
      for (std::uint32_t t = 0; t < tets.size(); ++t)
        ++mt.fine_begin[creator[t] + 1];
      for (std::uint32_t j = 0; j < n_nodes; ++j)
        mt.fine_begin[j + 1] += mt.fine_begin[j];
      std::vector<std::uint32_t> new_id(tets.size());
      {
        std::vector<std::uint32_t> next(mt.fine_begin.begin(), mt.fine_begin.end() - 1);
        for (std::uint32_t t = 0; t < tets.size(); ++t)
          new_id[t] = next[creator[t]]++;
      }
      mt.tets.resize(tets.size());
      mt.creator.resize(tets.size());
      mt.destroyer.resize(tets.size());
      for (std::uint32_t t = 0; t < tets.size(); ++t)
      {
        mt.tets[new_id[t]]      = tets[t];
        mt.creator[new_id[t]]   = creator[t];
        mt.destroyer[new_id[t]] = destroyer[t];
      }
      mt.coarse_begin.assign(n_nodes + 1, 0);
      mt.node_vertex.assign(n_nodes, none);
      mt.vertex_node.assign(position.size(), 0);
      for (std::uint32_t j = 1; j < n_nodes; ++j)
      {
        const std::uint32_t k = K - j;
        for (auto [i, end] = range(created_begin, created_list, k); i != end; ++i)
          mt.coarse_list.push_back(new_id[*i]);
        mt.coarse_begin[j + 1] = static_cast<std::uint32_t>(mt.coarse_list.size());
        mt.node_vertex[j]      = removed_vertex[k];
        mt.vertex_node[removed_vertex[k]] = j;
      }

      // Errors and balls, children (earlier collapses, larger node ids) first.
      mt.error.assign(n_nodes, 0);
      mt.ball.assign(n_nodes, {{0, 0, 0, 0}});
      mt.own_error.assign(n_nodes, 0);
      mt.own_ball.assign(n_nodes, {{0, 0, 0, 0}});
      const auto volume = [&](const std::uint32_t t)
      {
        const Tet &c = mt.tets[t];
        return mesh::signed_volume(position[c[0]],
                                   position[c[1]],
                                   position[c[2]],
                                   position[c[3]]);
      };
      for (std::uint32_t j = n_nodes; j-- > 0;)
      {
        std::vector<std::uint32_t> points;
        double                     sum = 0;
        for (std::uint32_t i = mt.coarse_begin[j]; i < mt.coarse_begin[j + 1]; ++i)
        {
          sum += volume(mt.coarse_list[i]);
          points.insert(points.end(),
                        mt.tets[mt.coarse_list[i]].begin(),
                        mt.tets[mt.coarse_list[i]].end());
        }
        for (std::uint32_t t = mt.fine_begin[j]; t < mt.fine_begin[j + 1]; ++t)
          points.insert(points.end(), mt.tets[t].begin(), mt.tets[t].end());
        sort_unique(points);
        Point3 center = {{0, 0, 0}};
        for (const std::uint32_t p : points)
          for (unsigned int d = 0; d < 3; ++d)
            center[d] += position[p][d] / points.size();
        double radius = 0;
        for (const std::uint32_t p : points)
          radius = std::max(radius, distance(center, position[p]));
        double error    = mt.n_coarse(j) > 0 ? sum / mt.n_coarse(j) : 0;
        mt.own_error[j] = error;
        mt.own_ball[j]  = {{center[0], center[1], center[2], radius * (1 + 1e-12)}};
        for (std::uint32_t t = mt.fine_begin[j]; t < mt.fine_begin[j + 1]; ++t)
          if (const std::uint32_t c = mt.destroyer[t]; c != none)
          {
            error         = std::max(error, mt.error[c]);
            const auto &b = mt.ball[c];
            radius = std::max(radius, distance(center, {{b[0], b[1], b[2]}}) + b[3]);
          }
        // Round the radius up so that containment survives rounding.
        mt.error[j] = error;
        mt.ball[j]  = {{center[0], center[1], center[2], radius * (1 + 1e-12)}};
      }
      return mt;
    }
  } // namespace


  double
  tet_quality(const Point3 &a, const Point3 &b, const Point3 &c, const Point3 &d)
  {
    const double volume = mesh::signed_volume(a, b, c, d);
    if (!(volume > 0))
      return volume < 0 ? -1 : 0;
    double squares = 0;
    for (const auto &[p, q] : {std::pair(&a, &b),
                               std::pair(&a, &c),
                               std::pair(&a, &d),
                               std::pair(&b, &c),
                               std::pair(&b, &d),
                               std::pair(&c, &d)})
    {
      const Point3 e = sub(*p, *q);
      squares += dot(e, e);
    }
    return 12 * std::cbrt(9 * volume * volume) / squares;
  }


  MultiTriangulation
  build_multi_triangulation(const mesh::TetMesh             &mesh,
                            const BuilderParameters         &parameters,
                            const std::vector<unsigned int> &locked)
  {
    Decimator decimator(mesh, parameters, locked);
    decimator.run();
    return decimator.assemble();
  }
} // namespace lacerta::mt
