#include <lacerta/base/exceptions.h>
#include <lacerta/cut/cutter.h>
#include <lacerta/physics/assembly.h>
#include <lacerta/physics/particle_system.h>

#include <deal.II/base/function.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <map>
#include <numeric>
#include <set>

namespace lacerta::cut
{
  namespace
  {
    using Clock = std::chrono::steady_clock;

    std::array<unsigned int, 3>
    sorted3(unsigned int a, unsigned int b, unsigned int c)
    {
      std::array<unsigned int, 3> f{{a, b, c}};
      std::sort(f.begin(), f.end());
      return f;
    }

    /// Union-find on small index sets.
    struct Groups
    {
      std::vector<std::size_t> parent;
      explicit Groups(const std::size_t n)
          : parent(n)
      {
        std::iota(parent.begin(), parent.end(), 0);
      }
      std::size_t
      find(std::size_t i)
      {
        while (parent[i] != i)
          i = parent[i] = parent[parent[i]];
        return i;
      }
      void
      join(const std::size_t a, const std::size_t b)
      {
        parent[find(a)] = find(b);
      }
    };

    /// Whether local node @p n of a child lies on local face @p f of its parent.
    bool
    node_on_parent_face(const NodeRef &n, const unsigned int f)
    {
      switch (n.kind)
      {
        case NodeKind::vertex:
          return n.index != f;
        case NodeKind::edge_point:
          return tet_edge_vertices[n.index][0] != f && tet_edge_vertices[n.index][1] != f;
        case NodeKind::face_point:
          return n.index == f;
        case NodeKind::interior_point:
          return false;
      }
      return false;
    }
  } // namespace


  void
  Cutter::declare_parameters(dealii::ParameterHandler &prm)
  {
    prm.enter_subsection("Cut");
    prm.declare_entry("Snap fraction",
                      "0.05",
                      dealii::Patterns::Double(0.001, 0.45),
                      "A cut point closer than this fraction of its edge to an end "
                      "snaps onto that end (doc/split-table.md): no sliver is created.");
    prm.declare_entry("Max advance",
                      "0.5",
                      dealii::Patterns::Double(0.01, 10.0),
                      "A blade motion is split into sweeps that advance at most this "
                      "fraction of the local edge length, so that a fast scalpel never "
                      "crosses an element undetected.");
    prm.leave_subsection();
  }


  Cutter::Parameters
  Cutter::parse_parameters(dealii::ParameterHandler &prm)
  {
    prm.enter_subsection("Cut");
    Parameters p;
    p.snap_fraction = prm.get_double("Snap fraction");
    p.max_advance   = prm.get_double("Max advance");
    prm.leave_subsection();
    return p;
  }


  Cutter::Cutter(mesh::TetMesh                     &mesh_in,
                 physics::ParticleSystem           &system_in,
                 const dealii::Function<3, double> &density_in,
                 const dealii::Function<3, double> &youngs_modulus_in,
                 double                            &integral,
                 const Parameters                  &parameters_in,
                 const Blade                       &initial)
      : mesh(mesh_in)
      , system(system_in)
      , density(density_in)
      , youngs_modulus(youngs_modulus_in)
      , integral_of_density(integral)
      , parameters(parameters_in)
      , current(initial)
      , front(initial)
  {
    mesh.enable_local_updates();
    std::vector<double> lengths;
    for (const auto &e : mesh.get_edges())
      lengths.push_back(norm(sub(mesh.vertex(e[1]), mesh.vertex(e[0]))));
    std::nth_element(lengths.begin(),
                     lengths.begin() + lengths.size() / 2,
                     lengths.end());
    typical_edge = lengths[lengths.size() / 2];
    tree.build(mesh, system.position.data());
    tet_stamp.assign(mesh.n_tets(), 0);
    edge_stamp.assign(mesh.n_edges(), 0);
    on_surface.assign(mesh.n_vertices(), 0);
  }


  Point
  Cutter::position(const unsigned int v) const
  {
    const double *x = &system.position[3 * v];
    return {{x[0], x[1], x[2]}};
  }


  void
  Cutter::end_stroke()
  {
    for (const unsigned int v : on_surface_list)
      if (v < on_surface.size())
        on_surface[v] = 0;
    on_surface_list.clear();
  }


  bool
  Cutter::tet_meets(const unsigned int                         t,
                    const std::array<std::array<Point, 3>, 2> &swept) const
  {
    const mesh::Tet     &tet = mesh.tet(t);
    std::array<Point, 4> p;
    for (unsigned int i = 0; i < 4; ++i)
      p[i] = position(tet[i]);
    double s;
    for (const auto &tri : swept)
    {
      for (const auto &e : tet_edge_vertices)
        if (segment_hits_triangle(p[e[0]], p[e[1]], tri[0], tri[1], tri[2], s))
          return true;
      for (unsigned int f = 0; f < 4; ++f)
      {
        const auto &fv = mesh::TetMesh::face_vertices[f];
        for (unsigned int k = 0; k < 3; ++k)
          if (segment_hits_triangle(
                tri[k], tri[(k + 1) % 3], p[fv[0]], p[fv[1]], p[fv[2]], s))
            return true;
      }
      const auto l = barycentric(p[0], p[1], p[2], p[3], tri[0]);
      if (std::min({l[0], l[1], l[2], l[3]}) >= 0)
        return true;
    }
    return false;
  }


  bool
  Cutter::blade_in_tet(const unsigned int t, const Blade &b) const
  {
    const mesh::Tet     &tet = mesh.tet(t);
    std::array<Point, 4> p;
    for (unsigned int i = 0; i < 4; ++i)
      p[i] = position(tet[i]);
    double s;
    for (unsigned int f = 0; f < 4; ++f)
    {
      const auto &fv = mesh::TetMesh::face_vertices[f];
      if (segment_hits_triangle(b.tail, b.head, p[fv[0]], p[fv[1]], p[fv[2]], s))
        return true;
    }
    const auto l = barycentric(p[0], p[1], p[2], p[3], b.tail);
    return std::min({l[0], l[1], l[2], l[3]}) >= 0;
  }


  void
  Cutter::find_tets_to_cut(const std::array<std::array<Point, 3>, 2> &swept,
                           const Blade                               &end)
  {
    tet_stamp.resize(mesh.n_tets(), 0);
    edge_stamp.resize(mesh.n_edges(), 0);
    ++stamp;
    candidates.clear();
    next_active.clear();
    queue.clear();
    const auto push = [&](const unsigned int t)
    {
      if (t < mesh.n_tets() && tet_stamp[t] != stamp)
      {
        tet_stamp[t] = stamp;
        queue.push_back(t);
      }
    };
    for (const unsigned int t : active)
      push(t);
    // First contact: the swept triangles against the boundary faces, through the tree.
    Box box;
    for (const auto &tri : swept)
      for (const Point &p : tri)
        box.extend(p);
    hits.clear();
    tree.query(mesh, box, hits);
    for (const auto &f : hits)
    {
      const auto tri = BoundaryFaceTree::triangle(f, system.position.data());
      if (triangles_intersect(tri, swept[0]) || triangles_intersect(tri, swept[1]))
        push(f.tet);
    }
    // Propagation: through the cells around every intersected edge (each edge tested
    // once per sweep), no global search.
    std::vector<unsigned int> around;
    for (std::size_t q = 0; q < queue.size(); ++q)
    {
      const unsigned int t = queue[q];
      if (!tet_meets(t, swept))
        continue;
      candidates.push_back(t);
      bool crossed_edge = false;
      for (unsigned int e = 0; e < 6; ++e)
      {
        const unsigned int id = mesh.tet_edges(t)[e];
        if (edge_stamp[id] == stamp)
          continue;
        edge_stamp[id]       = stamp;
        const unsigned int a = mesh.tet(t)[tet_edge_vertices[e][0]];
        const unsigned int b = mesh.tet(t)[tet_edge_vertices[e][1]];
        double             s;
        if (segment_hits_triangle(
              position(a), position(b), swept[0][0], swept[0][1], swept[0][2], s)
            || segment_hits_triangle(
              position(a), position(b), swept[1][0], swept[1][1], swept[1][2], s))
        {
          crossed_edge = true;
          around.clear();
          mesh.tets_around_edge(a, b, around);
          for (const unsigned int n : around)
            push(n);
        }
      }
      // The surface can enter a cell through a face without crossing its edges (a
      // small sweep inside one cell): look across the faces then.
      if (!crossed_edge)
        for (unsigned int f = 0; f < 4; ++f)
          push(mesh.neighbor(t, f));
      if (blade_in_tet(t, end))
        next_active.push_back(t);
    }
  }


  CutStepStatistics
  Cutter::move_blade(const Blade &next)
  {
    CutStepStatistics statistics;
    const double      advance =
      std::max(norm(sub(next.tail, current.tail)), norm(sub(next.head, current.head)));
    if (!(advance > 0))
      return statistics;
    tree.refit(mesh, system.position.data());
    // The local element size: the median edge of the active cells (deformed), or of
    // the mesh when the blade is outside. Not the shortest: cells a cut made small
    // must not multiply the sweeps, each of which re-splits the cells at the front.
    double h = typical_edge;
    if (!active.empty())
    {
      std::vector<double> lengths;
      for (const unsigned int t : active)
        for (const auto &e : tet_edge_vertices)
          lengths.push_back(
            norm(sub(position(mesh.tet(t)[e[1]]), position(mesh.tet(t)[e[0]]))));
      std::nth_element(lengths.begin(),
                       lengths.begin() + lengths.size() / 2,
                       lengths.end());
      h = std::max(lengths[lengths.size() / 2], 0.1 * typical_edge);
    }
    const unsigned int n = std::max(
      1u, static_cast<unsigned int>(std::ceil(advance / (parameters.max_advance * h))));
    const Blade start = current;
    for (unsigned int k = 1; k <= n; ++k)
    {
      const double s = double(k) / n;
      sweep({lerp(start.tail, next.tail, s), lerp(start.head, next.head, s)}, statistics);
    }
    current = next;
    if (statistics.changed)
    {
      const auto t0 = Clock::now();
      system.refresh_force_model();
      statistics.reinit_seconds =
        std::chrono::duration<double>(Clock::now() - t0).count();
    }
    return statistics;
  }


  void
  Cutter::sweep(const Blade &end, CutStepStatistics &statistics)
  {
    ++statistics.sweeps;
    const Blade                              &s     = front;
    const std::array<std::array<Point, 3>, 2> swept = {
      {{{s.tail, s.head, end.tail}}, {{end.tail, s.head, end.head}}}};
    find_tets_to_cut(swept, end);
    active.swap(next_active);
    if (candidates.empty())
    {
      // Out of the tissue: the stroke is over.
      front = end;
      end_stroke();
      n_postponed = 0;
      return;
    }

    // The cut surface of this sweep in the deformed configuration: the plane through
    // the last crack front along the motion, and the new crack front.
    const Point motion =
      sub(scale(0.5, add(end.tail, end.head)), scale(0.5, add(s.tail, s.head)));
    Point normal = cross(sub(s.head, s.tail), motion);
    if (!(norm(normal) > 1e-12 * norm(sub(s.head, s.tail)) * norm(motion)))
    {
      // The blade moved along itself: it sweeps no surface.
      front = end;
      return;
    }
    normal                = normalized(normal);
    const Point origin    = s.tail;
    Point       front_dir = normalized(cross(normal, sub(end.head, end.tail)));
    if (dot(front_dir, motion) < 0)
      front_dir = scale(-1, front_dir);
    const auto distance = [&](const Point &x) { return dot(normal, sub(x, origin)); };
    const auto behind = [&](const Point &x) { return dot(front_dir, sub(x, end.tail)); };
    const double eps  = parameters.snap_fraction;
    const double zero = 1e-12 * typical_edge;

    const auto t_start = Clock::now();
    // The affected set: C, closed under the stars of cut edges, front faces and
    // vertices joining the crack (all of which must be split alike).
    std::vector<unsigned int>                               affected = candidates;
    std::map<unsigned int, double>                          d;
    std::map<unsigned int, std::int8_t>                     side;
    std::map<std::pair<unsigned int, unsigned int>, double> edge_t; // cut edges
    std::map<std::array<unsigned int, 3>, std::pair<Point, Point>>
                                 front_points; // rest, deformed
    std::set<unsigned int>       in_set(affected.begin(), affected.end());
    std::set<unsigned int>       needs_star;
    std::map<unsigned int, bool> on_plane_final;
    bool                         closed = false;
    for (unsigned int iteration = 0; iteration < 6 && !closed; ++iteration)
    {
      d.clear();
      side.clear();
      edge_t.clear();
      front_points.clear();
      std::set<std::pair<unsigned int, unsigned int>> edges;
      for (const unsigned int t : affected)
      {
        const mesh::Tet &tet = mesh.tet(t);
        for (const auto &e : tet_edge_vertices)
          edges.insert({std::min(tet[e[0]], tet[e[1]]), std::max(tet[e[0]], tet[e[1]])});
        for (const unsigned int v : tet)
          if (!d.count(v))
          {
            double dv = distance(position(v));
            if (std::abs(dv) <= zero)
              dv = 0;
            d[v] = dv;
          }
      }
      // Snapping: a vertex on the surface (exactly, kept from earlier sweeps of the
      // stroke, or snapped by a crossing close to it) has no cut edge.
      std::map<unsigned int, bool> on_plane, reached;
      std::vector<unsigned int>    verts;
      for (const auto &[v, dv] : d)
      {
        verts.push_back(v);
        const double local = eps * typical_edge;
        on_plane[v] =
          dv == 0 || (v < on_surface.size() && on_surface[v] && std::abs(dv) <= local);
        reached[v] = behind(position(v)) < 0;
      }
      for (const auto &[a, b] : edges)
        if (!on_plane[a] && !on_plane[b] && d[a] * d[b] < 0)
        {
          const EdgeSnap snap = snap_edge_parameter(d[a] / (d[a] - d[b]), eps);
          if (snap == EdgeSnap::first_vertex)
            on_plane[a] = true;
          else if (snap == EdgeSnap::second_vertex)
            on_plane[b] = true;
        }
      // Vertices on the surface joined by edges in the surface are reached together.
      {
        Groups     groups(verts.size());
        const auto index = [&](unsigned int v)
        { return std::lower_bound(verts.begin(), verts.end(), v) - verts.begin(); };
        for (const auto &[a, b] : edges)
          if (on_plane[a] && on_plane[b])
            groups.join(index(a), index(b));
        std::vector<bool> all(verts.size(), true);
        for (std::size_t i = 0; i < verts.size(); ++i)
          if (on_plane[verts[i]] && !reached[verts[i]])
            all[groups.find(i)] = false;
        for (std::size_t i = 0; i < verts.size(); ++i)
          if (on_plane[verts[i]])
            reached[verts[i]] = all[groups.find(i)];
      }
      for (const unsigned int v : verts)
        side[v] = on_plane[v] && reached[v] ? 0 : (d[v] >= 0 ? 1 : -1);
      on_plane_final = on_plane;
      // Crossings of the surface; the reached ones are cut.
      std::map<std::pair<unsigned int, unsigned int>, bool> crossing_reached;
      for (const auto &[a, b] : edges)
        if (!on_plane[a] && !on_plane[b] && d[a] * d[b] < 0)
        {
          const double t = d[a] / (d[a] - d[b]);
          const Point  p = lerp(position(a), position(b), t);
          // The plane of this sweep reaches back only to its start line (within a
          // cell): at a corner of the path it must not cut on along the old crack.
          if (dot(motion, sub(p, origin)) < -typical_edge * norm(motion))
            continue;
          const bool r             = behind(p) < 0;
          crossing_reached[{a, b}] = r;
          if (r)
            edge_t[{a, b}] = t;
        }
      // Front points, once per face, from the face's two section corners.
      std::set<std::array<unsigned int, 3>> faces;
      for (const unsigned int t : affected)
        for (const auto &fv : mesh::TetMesh::face_vertices)
          faces.insert(
            sorted3(mesh.tet(t)[fv[0]], mesh.tet(t)[fv[1]], mesh.tet(t)[fv[2]]));
      for (const auto &f : faces)
      {
        struct Corner
        {
          Point rest, now;
          bool  reached;
        };
        std::vector<Corner> corners;
        unsigned int        vertex_corners = 0;
        for (unsigned int k = 0; k < 3; ++k)
          if (on_plane[f[k]])
          {
            corners.push_back({mesh.vertex(f[k]), position(f[k]), reached[f[k]]});
            ++vertex_corners;
          }
        for (unsigned int k = 0; k < 3; ++k)
          for (unsigned int l = k + 1; l < 3; ++l)
          {
            const auto it = crossing_reached.find({f[k], f[l]});
            if (it == crossing_reached.end())
              continue;
            const double t = d[f[k]] / (d[f[k]] - d[f[l]]);
            corners.push_back({lerp(mesh.vertex(f[k]), mesh.vertex(f[l]), t),
                               lerp(position(f[k]), position(f[l]), t),
                               it->second});
          }
        if (corners.size() != 2 || corners[0].reached == corners[1].reached
            || vertex_corners == 2)
          continue;
        const Corner &r  = corners[0].reached ? corners[0] : corners[1];
        const Corner &u  = corners[0].reached ? corners[1] : corners[0];
        const double  pr = behind(r.now), pu = behind(u.now);
        const double  t = clamp_front_parameter(pr / (pr - pu), eps);
        front_points[f] = {lerp(r.rest, u.rest, t), lerp(r.now, u.now, t)};
      }
      // Closure: everything that must be split alike has to be in the set.
      std::vector<unsigned int> missing, around;
      for (const auto &[e, t] : edge_t)
      {
        around.clear();
        mesh.tets_around_edge(e.first, e.second, around);
        for (const unsigned int n : around)
          if (!in_set.count(n))
            missing.push_back(n);
      }
      // A vertex joining the crack needs its whole star (its copies are decided on
      // it): a vertex newly on the surface, or one of a cell that is cut now. Old
      // crack vertices elsewhere stay as they are, so the set does not spread along
      // the whole crack.
      needs_star.clear();
      for (const unsigned int t : affected)
      {
        const mesh::Tet &tet    = mesh.tet(t);
        bool             is_cut = false;
        for (const auto &e : tet_edge_vertices)
          is_cut = is_cut
                   || edge_t.count(
                     {std::min(tet[e[0]], tet[e[1]]), std::max(tet[e[0]], tet[e[1]])});
        for (const auto &fv : mesh::TetMesh::face_vertices)
          is_cut =
            is_cut || front_points.count(sorted3(tet[fv[0]], tet[fv[1]], tet[fv[2]]));
        for (const unsigned int v : tet)
          if (side[v] == 0 && (is_cut || v >= on_surface.size() || !on_surface[v]))
            needs_star.insert(v);
      }
      for (const unsigned int v : needs_star)
        for (const unsigned int n : mesh.tets_of_vertex(v))
          if (!in_set.count(n))
            missing.push_back(n);
      for (const auto &[f, p] : front_points)
      {
        around.clear();
        mesh.tets_around_edge(f[0], f[1], around);
        for (const unsigned int n : around)
        {
          const mesh::Tet &q = mesh.tet(n);
          if (std::find(q.begin(), q.end(), f[2]) != q.end() && !in_set.count(n))
            missing.push_back(n);
        }
      }
      closed = missing.empty();
      for (const unsigned int n : missing)
        if (in_set.insert(n).second)
          affected.push_back(n);
    }
    if (!closed)
    {
      ++statistics.postponed;
      return;
    }
    // One TetCut per affected tetrahedron; split them all before changing anything.
    std::vector<unsigned int> removed;
    std::vector<TetCut>       cuts;
    for (const unsigned int t : affected)
    {
      const mesh::Tet &tet = mesh.tet(t);
      TetCut           c;
      bool             touched = false;
      for (unsigned int i = 0; i < 4; ++i)
      {
        c.vertex_ids[i]  = tet[i];
        c.points[i]      = mesh.vertex(tet[i]);
        c.vertex_side[i] = side[tet[i]];
        touched |= needs_star.count(tet[i]) > 0;
      }
      for (unsigned int e = 0; e < 6; ++e)
      {
        const unsigned int a = tet[tet_edge_vertices[e][0]],
                           b = tet[tet_edge_vertices[e][1]];
        const auto it        = edge_t.find({std::min(a, b), std::max(a, b)});
        if (it != edge_t.end())
        {
          c.cut_edges |= std::uint8_t(1u << e);
          c.edge_parameter[e] = it->second;
          touched             = true;
        }
      }
      for (unsigned int f = 0; f < 4; ++f)
      {
        const auto &fv = mesh::TetMesh::face_vertices[f];
        const auto  it = front_points.find(sorted3(tet[fv[0]], tet[fv[1]], tet[fv[2]]));
        if (it != front_points.end())
        {
          c.front_faces |= std::uint8_t(1u << f);
          c.front_points[f] = it->second.first;
          touched           = true;
        }
      }
      if (touched)
      {
        removed.push_back(t);
        cuts.push_back(c);
      }
    }
    if (removed.empty())
    {
      front = end;
      return;
    }
    std::vector<SplitResult> results(cuts.size());
    bool                     separates = false;
    for (std::size_t k = 0; k < cuts.size(); ++k)
    {
      const CutKind kind = split_tetrahedron(cuts[k], results[k], eps);
      if (kind == CutKind::unsupported)
      {
        // Postpone: the crack front waits until the configuration is one the table
        // describes; after a few tries the stroke restarts from the blade.
        if (++n_postponed > 8)
        {
          front = end;
          end_stroke();
          n_postponed = 0;
        }
        ++statistics.postponed;
        return;
      }
      separates |= kind == CutKind::complete || kind == CutKind::partial;
      // A partial split can leave a sliver next to a vertex ahead of the front (its
      // crossing is not cut yet, so it has not snapped; doc/split-table.md). Such a
      // split is postponed until the crack has left the cell, when the complete split
      // is the one-stroke split and keeps its edges long.
      // Every child must be a sound element at rest: a vertex kept on the surface
      // from an earlier sweep lies within ε of the plane, not on it, and the table's
      // children through it can then be flat. Postponed like the slivers below.
      double longest_parent = 0;
      for (const auto &e : tet_edge_vertices)
        longest_parent =
          std::max(longest_parent, norm(sub(cuts[k].points[e[1]], cuts[k].points[e[0]])));
      for (unsigned int i = 0; i < results[k].n_children; ++i)
      {
        std::array<Point, 4> p;
        for (unsigned int j = 0; j < 4; ++j)
        {
          const NodeRef &n = results[k].children[i].nodes[j];
          p[j]             = n.kind == NodeKind::vertex       ? cuts[k].points[n.index]
                             : n.kind == NodeKind::edge_point ? results[k].edge_points[n.index]
                             : n.kind == NodeKind::face_point ? results[k].face_points[n.index]
                                                              : results[k].interior_point;
        }
        if (!(volume(p[0], p[1], p[2], p[3])
              > 1e-6 * longest_parent * longest_parent * longest_parent))
        {
          if (++n_postponed > 8)
          {
            front = end;
            end_stroke();
            n_postponed = 0;
          }
          ++statistics.postponed;
          return;
        }
      }
      if (kind == CutKind::partial || kind == CutKind::refinement)
      {
        double shortest_parent = 1e300;
        for (const auto &e : tet_edge_vertices)
          shortest_parent =
            std::min(shortest_parent,
                     norm(sub(cuts[k].points[e[1]], cuts[k].points[e[0]])));
        if (shortest_child_edge(cuts[k], results[k]) < 0.5 * eps * shortest_parent)
        {
          ++statistics.postponed;
          return;
        }
      }
    }
    n_postponed = 0;
    if (!separates
        && std::all_of(results.begin(),
                       results.end(),
                       [](const SplitResult &r)
                       { return r.kind == CutKind::none || r.kind == CutKind::touch; })
        && edge_t.empty())
    {
      // Only touching: nothing to change yet (vertices on the surface wait).
      front = end;
      return;
    }

    // The record of this sweep for the Multi-Triangulation (set_recorder()).
    CutRecord *record = recorder ? &recorder->emplace_back() : nullptr;
    if (record)
      record->cuts = cuts;

    // Mass and stiffness contributions of the tetrahedra that go.
    std::map<unsigned int, double>                              mass_delta;
    std::vector<std::pair<std::array<unsigned int, 2>, double>> stiffness_delta;
    double                                                      integral_delta = 0;
    for (const unsigned int r : removed)
    {
      const auto m = physics::tet_mass_contributions(mesh, r, density);
      for (unsigned int i = 0; i < 4; ++i)
      {
        mass_delta[mesh.tet(r)[i]] -= m[i];
        integral_delta -= m[i];
      }
      const double f = physics::tet_stiffness_factor(mesh, r, youngs_modulus);
      for (const auto &e : tet_edge_vertices)
        stiffness_delta.push_back({{{mesh.tet(r)[e[0]], mesh.tet(r)[e[1]]}}, -f});
    }

    // New points, merged across tetrahedra by their keys; state interpolated from the
    // parent (the same affine map at rest and deformed).
    std::map<PointKey, unsigned int>         ids;
    std::vector<mesh::Tet>                   children;
    std::vector<std::array<unsigned int, 4>> face_ids;
    std::set<std::array<unsigned int, 3>>    cut_faces;
    std::vector<std::array<unsigned int, 2>> child_origin; // (split, child), recording
    const auto new_particle = [&](const Point &rest, const unsigned int parent)
    {
      const mesh::Tet &tet = mesh.tet(parent);
      const auto       l   = barycentric(mesh.vertex(tet[0]),
                                 mesh.vertex(tet[1]),
                                 mesh.vertex(tet[2]),
                                 mesh.vertex(tet[3]),
                                 rest);
      Point            x{{0, 0, 0}}, v{{0, 0, 0}};
      for (unsigned int i = 0; i < 4; ++i)
        for (unsigned int c = 0; c < 3; ++c)
        {
          x[c] += l[i] * system.position[3 * tet[i] + c];
          v[c] += l[i] * system.velocity[3 * tet[i] + c];
        }
      const unsigned int id = mesh.add_vertex(rest);
      system.add_particle(rest, x, v);
      on_surface.resize(mesh.n_vertices(), 0);
      ++statistics.new_particles;
      return id;
    };
    for (std::size_t k = 0; k < cuts.size(); ++k)
    {
      const TetCut      &c = cuts[k];
      const SplitResult &r = results[k];
      for (unsigned int i = 0; i < r.n_children; ++i)
      {
        const Child &child = r.children[i];
        mesh::Tet    t;
        for (unsigned int j = 0; j < 4; ++j)
        {
          const NodeRef &n = child.nodes[j];
          if (n.kind == NodeKind::vertex)
          {
            t[j] = static_cast<unsigned int>(c.vertex_ids[n.index]);
            continue;
          }
          const PointKey key = point_key(c.vertex_ids, n, removed[k]);
          const auto     it  = ids.find(key);
          if (it != ids.end())
            t[j] = it->second;
          else
          {
            const Point p = n.kind == NodeKind::edge_point   ? r.edge_points[n.index]
                            : n.kind == NodeKind::face_point ? r.face_points[n.index]
                                                             : r.interior_point;
            t[j]          = new_particle(p, removed[k]);
            if (n.kind != NodeKind::interior_point)
            {
              on_surface[t[j]] = 1;
              on_surface_list.push_back(t[j]);
            }
            ids.emplace(key, t[j]);
            if (record)
            {
              CutRecord::NewPoint point{t[j], n.kind, key.side, {}, p};
              for (unsigned int m = 0; m < 4; ++m)
                point.ids[m] = n.kind == NodeKind::interior_point
                                 ? static_cast<unsigned int>(c.vertex_ids[m])
                                 : (m < 3 ? static_cast<unsigned int>(key.ids[m]) : 0);
              std::sort(point.ids.begin(),
                        point.ids.begin() + (n.kind == NodeKind::interior_point ? 4 : 0));
              record->new_points.push_back(point);
            }
          }
        }
        std::array<unsigned int, 4> fid{{0, 0, 0, 0}};
        for (unsigned int j = 0; j < 4; ++j)
        {
          if (child.cut_faces & (1u << j))
          {
            cut_faces.insert(sorted3(t[(j + 1) % 4], t[(j + 2) % 4], t[(j + 3) % 4]));
            fid[j] = cut_boundary_id;
            continue;
          }
          // A face on a parent's boundary face keeps its boundary id.
          for (unsigned int f = 0; f < 4; ++f)
          {
            bool on = true;
            for (unsigned int m = 0; m < 4; ++m)
              if (m != j)
                on = on && node_on_parent_face(child.nodes[m], f);
            const unsigned int id = mesh.boundary_id(removed[k], f);
            if (on && id != mesh::invalid_index)
              fid[j] = id;
          }
        }
        children.push_back(t);
        face_ids.push_back(fid);
        if (record)
          child_origin.push_back({{static_cast<unsigned int>(k), i}});
      }
    }
    // Vertices on the cut: one copy per group of their children connected through
    // faces not on the cut, so that the two sides separate where the crack is open
    // and stay joined at the crack tip.
    std::map<unsigned int, std::vector<std::size_t>> incident;
    for (std::size_t k = 0; k < children.size(); ++k)
      for (const unsigned int v : children[k])
        if (needs_star.count(v))
          incident[v].push_back(k);
    for (const auto &[v, list] : incident)
    {
      Groups                                             groups(list.size());
      std::map<std::array<unsigned int, 3>, std::size_t> first_with_face;
      for (std::size_t i = 0; i < list.size(); ++i)
      {
        const mesh::Tet &t = children[list[i]];
        for (unsigned int f = 0; f < 4; ++f)
        {
          const auto face = sorted3(t[(f + 1) % 4], t[(f + 2) % 4], t[(f + 3) % 4]);
          if (t[f] == v || cut_faces.count(face))
            continue;
          const auto [it, inserted] = first_with_face.emplace(face, i);
          if (!inserted)
            groups.join(i, it->second);
        }
      }
      std::map<std::size_t, unsigned int> copy_of_root;
      for (std::size_t i = 0; i < list.size(); ++i)
      {
        const std::size_t root = groups.find(i);
        if (copy_of_root.empty())
          copy_of_root[root] = v;
        auto it = copy_of_root.find(root);
        if (it == copy_of_root.end())
        {
          const unsigned int copy = mesh.add_vertex(mesh.vertex(v));
          system.add_particle(mesh.vertex(v),
                              position(v),
                              {{system.velocity[3 * v],
                                system.velocity[3 * v + 1],
                                system.velocity[3 * v + 2]}});
          on_surface.resize(mesh.n_vertices(), 0);
          on_surface[copy] = 1;
          on_surface_list.push_back(copy);
          ++statistics.new_particles;
          it = copy_of_root.emplace(root, copy).first;
          if (record)
            record->new_points.push_back(
              {copy, NodeKind::vertex, 0, {{v, 0, 0, 0}}, mesh.vertex(v)});
        }
        if (record)
          for (unsigned int m = 0; m < 4; ++m)
            if (children[list[i]][m] == v)
              record->vertex_choices.push_back(
                {child_origin[list[i]][0],
                 static_cast<std::uint8_t>(child_origin[list[i]][1]),
                 static_cast<std::uint8_t>(m),
                 it->second});
        for (auto &node : children[list[i]])
          if (node == v)
            node = it->second;
      }
    }
    for (const unsigned int v : needs_star)
      if (!on_surface[v])
      {
        on_surface[v] = 1;
        on_surface_list.push_back(v);
      }

    // The mesh, locally.
    std::vector<unsigned int> added_ids;
    mesh::TetMesh::EdgeUpdate edge_update;
    mesh.replace_tets(removed, children, face_ids, added_ids, edge_update);

    // Springs follow the edges: appended, moved into retired slots, restiffened.
    physics::SpringSet &springs = system.springs;
    const auto         &edges   = mesh.get_edges();
    for (unsigned int i = 0; i < edge_update.n_added; ++i)
    {
      const unsigned int e = static_cast<unsigned int>(springs.size());
      springs.push_back(edges[e][0],
                        edges[e][1],
                        0.0,
                        norm(sub(mesh.vertex(edges[e][1]), mesh.vertex(edges[e][0]))));
    }
    for (const auto &[to, from] : edge_update.moves)
    {
      springs.a[to]           = springs.a[from];
      springs.b[to]           = springs.b[from];
      springs.stiffness[to]   = springs.stiffness[from];
      springs.rest_length[to] = springs.rest_length[from];
      springs.a.pop_back();
      springs.b.pop_back();
      springs.stiffness.pop_back();
      springs.rest_length.pop_back();
    }
    for (const unsigned int t : added_ids)
    {
      const auto m = physics::tet_mass_contributions(mesh, t, density);
      for (unsigned int i = 0; i < 4; ++i)
      {
        mass_delta[mesh.tet(t)[i]] += m[i];
        integral_delta += m[i];
      }
      const double f = physics::tet_stiffness_factor(mesh, t, youngs_modulus);
      for (const auto &e : tet_edge_vertices)
        stiffness_delta.push_back({{{mesh.tet(t)[e[0]], mesh.tet(t)[e[1]]}}, f});
      for (unsigned int f2 = 0; f2 < 4; ++f2)
        if (mesh.neighbor(t, f2) == mesh::invalid_index)
          tree.add_face(mesh, t, f2);
    }
    for (const auto &[pair, f] : stiffness_delta)
    {
      const unsigned int e = mesh.find_edge(pair[0], pair[1]);
      if (e != mesh::invalid_index)
        springs.stiffness[e] += f / (springs.rest_length[e] * springs.rest_length[e]);
    }
    for (const auto &[v, dm] : mass_delta)
      system.mass[v] += dm;
    // A vertex that lost all its cells cannot happen (copies take over whole stars),
    // but a mass that rounding left a hair below zero would be nonsense: clamp.
    for (const auto &[v, dm] : mass_delta)
      if (system.mass[v] < 0)
        system.mass[v] = 0;
    integral_of_density += integral_delta;

    // The active cells: the new ones the blade is in.
    active.erase(std::remove_if(active.begin(),
                                active.end(),
                                [&](unsigned int t) { return in_set.count(t) > 0; }),
                 active.end());
    for (const unsigned int t : added_ids)
      if (blade_in_tet(t, end))
        active.push_back(t);

    statistics.cut_tets += static_cast<unsigned int>(removed.size());
    statistics.created_tets += static_cast<unsigned int>(children.size());
    statistics.changed = true;
    statistics.update_seconds +=
      std::chrono::duration<double>(Clock::now() - t_start).count();
    front = end;
  }
} // namespace lacerta::cut
