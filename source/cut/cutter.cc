#include <lacerta/base/exceptions.h>
#include <lacerta/cut/cutter.h>
#include <lacerta/physics/assembly.h>
#include <lacerta/physics/particle_system.h>

#include <deal.II/base/exceptions.h>
#include <deal.II/base/function.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <numeric>
#include <optional>

namespace lacerta::cut
{
  namespace
  {
    using Clock = std::chrono::steady_clock;

    /// How far (in typical edges) behind its start line a sweep's plane still cuts
    /// once the stroke has cut: rounding only. The part behind the last front is cut
    /// already (by the earlier plane, which differs at a corner of the path). The
    /// first cut of a stroke that plunged into the tissue reaches back one edge, so
    /// that the crack does not start inside a cell (the table has one front only).
    constexpr double start_tolerance = 1e-9;

    /// A blade motion that turns by more than this (radians, about 17 degrees) away
    /// from the direction since the crack front makes a corner of the path.
    constexpr double corner_angle = 0.3;

    /// The local faces of its parent that local node @p n of a child lies on, one bit
    /// per face.
    unsigned int
    parent_faces_of_node(const NodeRef &n)
    {
      switch (n.kind)
      {
        case NodeKind::vertex:
          return 0xFu & ~(1u << n.index);
        case NodeKind::edge_point:
          return 0xFu & ~(1u << tet_edge_vertices[n.index][0])
                 & ~(1u << tet_edge_vertices[n.index][1]);
        case NodeKind::face_point:
          return 1u << n.index;
        case NodeKind::interior_point:
          return 0;
      }
      return 0;
    }

    /// The local edges of face f's sides (face vertex k to k + 1): a table, since the
    /// analysis looks them up for every face of the affected cells.
    constexpr std::array<std::array<unsigned int, 3>, 4>
    make_face_edges()
    {
      std::array<std::array<unsigned int, 3>, 4> edges{};
      for (unsigned int f = 0; f < 4; ++f)
        for (unsigned int k = 0; k < 3; ++k)
        {
          const auto &fv = mesh::TetMesh::face_vertices[f];
          edges[f][k] =
            static_cast<unsigned int>(tet_edge_of_vertices[fv[k]][fv[(k + 1) % 3]]);
        }
      return edges;
    }
    constexpr std::array<std::array<unsigned int, 3>, 4> face_edges = make_face_edges();

    /// Barycentric coordinates of the rest point @p rest in cell @p t of @p mesh:
    /// the weights that carry it, with the cell's affine map, to the deformed state.
    std::array<double, 4>
    rest_barycentric(const mesh::TetMesh &mesh, const unsigned int t, const Point &rest)
    {
      const mesh::Tet &c = mesh.tet(t);
      return barycentric(
        mesh.vertex(c[0]), mesh.vertex(c[1]), mesh.vertex(c[2]), mesh.vertex(c[3]), rest);
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
      , last_end(initial)
  {
    // The split table is built on first use (about 10 ms): now, so that the first cut
    // of a run does not wait for it.
    split_table_entries();
    mesh.enable_local_updates();
    // Room for half as much again, so that the cuts of a stroke copy no mesh-sized
    // array (past it, the arrays double as usual: one copy, amortised).
    const auto room = [](const std::size_t n)
    { return static_cast<unsigned int>(n + n / 2 + 4096); };
    mesh.reserve(room(mesh.n_vertices()), room(mesh.n_tets()));
    system.reserve(room(system.n_particles()));
    system.springs.reserve(room(system.springs.size()));
    vertex_scratch.reserve(room(mesh.n_vertices()));
    on_surface.reserve(room(mesh.n_vertices()));
    joined_at.reserve(room(mesh.n_vertices()));
    swept.reserve(room(mesh.n_vertices()));
    crossing_pending.reserve(room(mesh.n_vertices()));
    edge_scratch.reserve(room(mesh.n_edges()));
    edge_stamp.reserve(room(mesh.n_edges()));
    face_scratch.reserve(4 * room(mesh.n_tets()));
    tet_mark.reserve(room(mesh.n_tets()));
    tet_stamp.reserve(room(mesh.n_tets()));
    partial_child.reserve(room(mesh.n_tets()));
    std::vector<double> lengths;
    for (const auto &e : mesh.get_edges())
      lengths.push_back(norm(sub(mesh.vertex(e[1]), mesh.vertex(e[0]))));
    std::nth_element(lengths.begin(),
                     lengths.begin() + lengths.size() / 2,
                     lengths.end());
    typical_edge = lengths[lengths.size() / 2];
    tree.build(mesh, system.position.data());
    if (const auto sigma = physics::constant_value(density))
      constant_density_mass.emplace(*sigma);
    else
      constant_density_mass.reset();
    constant_youngs_modulus = physics::constant_value(youngs_modulus);
    tet_stamp.assign(mesh.n_tets(), 0);
    edge_stamp.assign(mesh.n_edges(), 0);
    on_surface.assign(mesh.n_vertices(), 0);
    prepare_scratch();
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
    front_edges.clear();
    // Cells made by partial splits and vertices swept belong to this stroke only.
    ++stroke;
    stroke_has_cut = false;
    after_corner   = false;
    corner_pending = false;
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
    hits.clear();
    tree.query(mesh, system.position.data(), swept, hits);
    for (const auto &f : hits)
    {
      const auto tri = BoundaryFaceTree::triangle(f, system.position.data());
      if (triangles_intersect(tri, swept[0]) || triangles_intersect(tri, swept[1]))
        push(f.tet);
    }
    // Propagation: through the cells around every intersected edge (each edge tested
    // once per sweep), no global search.
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
    const auto t_refit = Clock::now();
    tree.refit(mesh, system.position.data());
    statistics.search_seconds +=
      std::chrono::duration<double>(Clock::now() - t_refit).count();
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
      system.springs_changed(changed_springs);
      statistics.reinit_seconds =
        std::chrono::duration<double>(Clock::now() - t0).count();
    }
    changed_springs.clear();
    return statistics;
  }


  void
  Cutter::sweep(const Blade &end, CutStepStatistics &statistics)
  {
    // A corner: the front lags behind the blade (it waits in a cell made by a partial
    // split, see below) and the blade turns away from the direction since the front.
    // A sweep from the waiting front to the blade would cut a chord across the corner
    // (and, crossing the crack's cells diagonally, often nothing at all, leaving the
    // corner uncut): the front is first brought to the corner, without waiting, so
    // that the next side starts from the corner line.
    // A catch-up that was postponed is retried towards the same corner: towards where
    // the blade was at the next sweep instead, the front would cut a chord across it.
    const auto  mid = [](const Blade &b) { return scale(0.5, add(b.tail, b.head)); };
    const Point a = sub(mid(last_end), mid(front)), b = sub(mid(end), mid(last_end));
    if (!corner_pending && norm(a) > 1e-12 * typical_edge && norm(b) > 0
        && dot(a, b) < std::cos(corner_angle) * norm(a) * norm(b))
    {
      corner         = last_end;
      corner_pending = true;
    }
    if (corner_pending)
    {
      catching_up = true;
      sweep_once(corner, statistics);
      catching_up = false;
      if (front.tail == corner.tail)
      {
        corner_pending = false;
        after_corner   = true;
      }
    }
    sweep_once(end, statistics);
    // The first sweep of the new side that advances the front ends the corner.
    if (front.tail == end.tail)
      after_corner = false;
    last_end = end;
  }


  void
  Cutter::sweep_once(const Blade &end, CutStepStatistics &statistics)
  {
    ++statistics.sweeps;
    const Blade                              &s               = front;
    const std::array<std::array<Point, 3>, 2> swept_triangles = {
      {{{s.tail, s.head, end.tail}}, {{end.tail, s.head, end.head}}}};
    const auto t_search = Clock::now();
    find_tets_to_cut(swept_triangles, end);
    statistics.search_seconds +=
      std::chrono::duration<double>(Clock::now() - t_search).count();
    active.swap(next_active);
    if (candidates.empty())
    {
      // Out of the tissue: the stroke is over.
      front = end;
      end_stroke();
      return;
    }

    // The cut surface of this sweep in the deformed configuration: the plane through
    // the last crack front along the motion, and the new crack front.
    SweepSurface surface;
    surface.motion =
      sub(scale(0.5, add(end.tail, end.head)), scale(0.5, add(s.tail, s.head)));
    Point normal = cross(sub(s.head, s.tail), surface.motion);
    if (!(norm(normal) > 1e-12 * norm(sub(s.head, s.tail)) * norm(surface.motion)))
    {
      // The blade moved along itself: it sweeps no surface.
      front = end;
      return;
    }
    surface.normal    = normalized(normal);
    surface.origin    = s.tail;
    surface.end_tail  = end.tail;
    surface.front_dir = normalized(cross(surface.normal, sub(end.head, end.tail)));
    if (dot(surface.front_dir, surface.motion) < 0)
      surface.front_dir = scale(-1, surface.front_dir);
    // The start line is the last front: in the plane, perpendicular to it, towards
    // the motion.
    surface.start_dir = normalized(cross(surface.normal, sub(s.head, s.tail)));
    if (dot(surface.start_dir, surface.motion) < 0)
      surface.start_dir = scale(-1, surface.start_dir);
    const double eps = parameters.snap_fraction;
    start_reach      = (stroke_has_cut ? start_tolerance : 1.0) * typical_edge;

    const auto t_start = Clock::now();
    lap_start          = t_start;
    const auto spent   = [&]
    {
      statistics.update_seconds +=
        std::chrono::duration<double>(Clock::now() - t_start).count();
    };
    prepare_scratch();
    // The affected set: C, closed under the stars of cut edges, front faces and
    // vertices joining the crack (all of which must be split alike).
    ++affected_stamp;
    affected = candidates;
    for (const unsigned int t : affected)
      tet_mark[t] = affected_stamp;
    // The crack tip stays where the last applied sweep left it, inside the cells of
    // the edges its plane crossed ahead of its front; the tissue moves meanwhile, and
    // those crossings can fall behind this sweep's start line, where a sweep does not
    // cut: the cell around the tip would stay whole and bridge the sides (square_hole
    // held still: the square stayed attached at its last corner in 5 of 30 runs whose
    // blade path differed by 1e-13 m). They are cut wherever the plane meets them,
    // and their cells join the set even if the swept surface has moved off them. Not
    // at a corner, where the crack turns and the part behind the start line belongs
    // to the other side.
    front_edge_ids.clear();
    if (!catching_up && !after_corner)
      for (const auto &ends : front_edges)
      {
        const unsigned int id = mesh.find_edge(ends[0], ends[1]);
        if (id == mesh::invalid_index)
          continue;
        front_edge_ids.push_back(id);
        around.clear();
        mesh.tets_around_edge(ends[0], ends[1], around);
        for (const unsigned int n : around)
          join_affected(n);
      }
    std::sort(front_edge_ids.begin(), front_edge_ids.end());
    analyse(surface);
    // One TetCut per affected tetrahedron; split them all before changing anything.
    removed.clear();
    cuts.clear();
    for (const unsigned int t : affected)
    {
      const mesh::Tet &tet = mesh.tet(t);
      TetCut           c;
      bool             touched = false;
      for (unsigned int i = 0; i < 4; ++i)
      {
        c.vertex_ids[i]  = tet[i];
        c.points[i]      = mesh.vertex(tet[i]);
        c.vertex_side[i] = vertex_scratch[tet[i]].side;
        touched |= vertex_scratch[tet[i]].star_stamp == star_stamp;
      }
      for (unsigned int e = 0; e < 6; ++e)
      {
        const EdgeScratch &es = edge_scratch[mesh.tet_edges(t)[e]];
        if (es.reached)
        {
          c.cut_edges |= std::uint8_t(1u << e);
          c.edge_parameter[e] = es.t;
          touched             = true;
        }
      }
      for (unsigned int f = 0; f < 4; ++f)
      {
        const FaceScratch &fs = face_scratch[4 * t + f];
        if (fs.has_front())
        {
          c.front_faces |= std::uint8_t(1u << f);
          c.front_points[f] = front_rest[fs.front];
          touched           = true;
        }
      }
      if (touched)
      {
        removed.push_back(t);
        cuts.push_back(c);
      }
    }
    lap(statistics.analysis_seconds);
    if (removed.empty())
    {
      // Nothing to split: the front stays where the crack is (see below).
      if (!stroke_has_cut)
        front = end;
      spent();
      return;
    }
    results.resize(cuts.size());
    bool separates = false, any_cut = false;
    for (std::size_t k = 0; k < cuts.size(); ++k)
    {
      const CutKind kind = split_tetrahedron(cuts[k], results[k], eps);
      // Postponed (the crack front waits; the next sweep, from the same front, covers
      // more): a configuration the table does not describe; a second partial split of
      // a cell the front has not left yet (it is continued when the front leaves it,
      // by the complete split of the children ahead of the old front, instead of
      // being re-split at every sweep); a child flat at rest (a vertex kept on the
      // surface lies within ε of the plane, not on it); a partial split that would
      // make a sliver next to a vertex ahead of the front.
      // (When the blade has left the tissue, or turned at a corner of its path, the
      // front must catch up where it is: no deferral and no waiting for a better
      // front.)
      const bool must_follow = active.empty() || catching_up;
      bool       postpone    = kind == CutKind::unsupported
                      || (kind == CutKind::partial && partial_child[removed[k]] == stroke
                          && !must_follow)
                      || has_flat_child(cuts[k], results[k]);
      if (!postpone && !must_follow
          && (kind == CutKind::partial || kind == CutKind::refinement))
      {
        double shortest_parent = 1e300;
        for (const auto &e : tet_edge_vertices)
          shortest_parent =
            std::min(shortest_parent,
                     norm(sub(cuts[k].points[e[1]], cuts[k].points[e[0]])));
        postpone = shortest_child_edge(cuts[k], results[k]) < 0.5 * eps * shortest_parent;
      }
      if (postpone)
      {
        ++statistics.postponed;
        lap(statistics.split_seconds);
        spent();
        return;
      }
      separates |= kind == CutKind::complete || kind == CutKind::partial;
      any_cut |= kind != CutKind::none && kind != CutKind::touch;
    }
    lap(statistics.split_seconds);
    if (!separates && !any_cut)
    {
      bool any_edge = false;
      for (const unsigned int e : edge_list)
        any_edge |= edge_scratch[e].reached;
      if (!any_edge)
      {
        // Only touching and nothing joins the crack: nothing to change yet.
        bool joins = false;
        for (const unsigned int v : verts)
          joins |= vertex_scratch[v].star_stamp == star_stamp;
        for (const unsigned int v : group_extra)
          joins |= vertex_scratch[v].star_stamp == star_stamp;
        if (!joins)
        {
          // Once the stroke has cut, the front stays where the crack is: a blade that
          // crosses an opened crack (a gap) or cuts inside one cell must not carry the
          // front past tissue it has not cut, since a sweep does not cut behind its
          // start line.
          if (!stroke_has_cut)
            front = end;
          spent();
          return;
        }
      }
    }
    apply(end, statistics);
    stroke_has_cut = true;
    spent();
    front = end;
  }


  bool
  Cutter::has_flat_child(const TetCut &cut, const SplitResult &result) const
  {
    // A child below 1e-6 of the parent's longest edge cubed is flat. At a corner of
    // the path the crack bends inside a cell, and a front point clamped off the
    // corner line (the line may run through a mesh face) leaves thin cells there:
    // they are accepted down to 1e-8, still a hundred times above what
    // check_invariants() calls flat, rather than postponing the new side forever.
    const double flat_volume = catching_up || after_corner ? 1e-8 : 1e-6;
    // One square root (the root is monotone: the same value as the longest norm).
    double longest_squared = 0;
    for (const auto &e : tet_edge_vertices)
    {
      const Point d   = sub(cut.points[e[1]], cut.points[e[0]]);
      longest_squared = std::max(longest_squared, dot(d, d));
    }
    const double longest_parent = std::sqrt(longest_squared);
    for (unsigned int i = 0; i < result.n_children; ++i)
    {
      const auto p = child_node_points(cut, result, result.children[i]);
      if (!(volume(p[0], p[1], p[2], p[3])
            > flat_volume * longest_parent * longest_parent * longest_parent))
        return true;
    }
    return false;
  }


  void
  Cutter::prepare_scratch()
  {
    vertex_scratch.resize(mesh.n_vertices());
    edge_scratch.resize(mesh.n_edges());
    face_scratch.resize(4 * std::size_t(mesh.n_tets()));
    tet_mark.resize(mesh.n_tets(), 0);
    partial_child.resize(mesh.n_tets(), 0);
    if (on_surface.size() < mesh.n_vertices())
      on_surface.resize(mesh.n_vertices(), 0);
    if (joined_at.size() < mesh.n_vertices())
      joined_at.resize(mesh.n_vertices());
    swept.resize(mesh.n_vertices(), 0);
    crossing_pending.resize(mesh.n_vertices(), 0);
  }


  Cutter::VertexScratch &
  Cutter::vertex_data(const unsigned int v, const SweepSurface &surface)
  {
    VertexScratch &s = vertex_scratch[v];
    if (s.stamp == analysis_stamp)
      return s;
    s.stamp  = analysis_stamp;
    s.parent = v;
    // Each pass of the analysis starts from the sweep's own judgement (the snapping
    // and the patches of a pass change on_plane and reached), which depends on the
    // sweep only: it is computed in the first pass that meets the vertex.
    if (s.sweep_stamp == affected_stamp)
    {
      s.on_plane = s.sweep_on_plane;
      s.reached  = s.sweep_reached;
      return s;
    }
    s.sweep_stamp = affected_stamp;
    const Point x = position(v);
    double      d = surface.distance(x);
    if (std::abs(d) <= 1e-12 * typical_edge)
      d = 0;
    s.d = d;
    // A vertex of the stroke's crack was put on the cut surface where the blade was
    // then; the crack opens behind the front (the sides move apart across the plane
    // as the stretched tissue relaxes, by several millimetres in square_hole), so
    // where it is now says little about whether a plane that continues the cut holds
    // it. Whether it is on the plane, and reached, is judged where it joined the crack.
    // The same holds for a fresh vertex an earlier sweep of the stroke put on the
    // plane and swept (a postponed sweep, or one whose patch waited): it stays
    // reached, and is judged where it was swept. Judged where it is now, the tissue
    // carried it off the plane (square_hole's third side: 0.9 mm, beyond ε of an edge)
    // while the front waited, and the sweep that finally applied put it on one side
    // behind its start line, where no crossing is cut, next to cells the earlier
    // sweeps had split with it on the plane: the cell between stayed whole and
    // bridged the sides.
    const double tolerance = parameters.snap_fraction * typical_edge;
    const bool   was_swept = !on_surface[v] && swept[v] == stroke;
    Point        at        = on_surface[v] || was_swept ? joined_at[v] : x;
    bool         on_crack =
      (on_surface[v] || was_swept) && std::abs(surface.distance(at)) <= tolerance;
    // Where the flap twists (square_hole's fourth side crossing the first side's
    // crack), neither place puts a crack vertex on the plane: it is then judged in
    // the rest frame of the tissue the blade is in, where crack vertices never move
    // (the plane meets the crack where it did at rest). The vertex's rest position
    // is mapped through the deformation of the blade's cells (the mean of their
    // affine maps), so that the test compares rest geometry in world units. Not while
    // the front is brought to a corner or has just turned there: the blade's cells
    // then hold the other side's crack (with the test there too, square_hole's third
    // corner stayed uncut between rest x = -0.0125 and -0.02).
    if (on_surface[v] && !on_crack && !active.empty() && !catching_up && !after_corner)
    {
      const Point &rest   = mesh.vertex(v);
      Point        mapped = {{0, 0, 0}};
      for (const unsigned int t : active)
      {
        const mesh::Tet &c = mesh.tet(t);
        const auto       l = rest_barycentric(mesh, t, rest);
        for (unsigned int i = 0; i < 4; ++i)
          mapped = add(mapped, scale(l[i] / active.size(), position(c[i])));
      }
      if (std::abs(surface.distance(mapped)) <= tolerance)
      {
        on_crack = true;
        at       = mapped;
      }
    }
    s.on_plane = d == 0 || on_crack;
    // Reached: a vertex of the crack when behind the new front; a fresh one when also
    // not behind the start of this sweep by more than a cell (the plane must not
    // reach back along an older part of the crack), or when an earlier sweep of the
    // stroke swept it. While the front is brought to a corner, a vertex of the crack
    // in the plane up to a quarter of an edge beyond the corner is reached too: where
    // a closed path comes back to its start, the corner is where the blade turned
    // between two steps, short of the crack's first vertices; a face in the plane
    // through one of them was cut only up to the corner, the next side's plane (which
    // turns away) never met the rest of it, and it held the disc (a closed
    // Catmull-Rom circle and a polygon of 64 sides per turn punched nothing).
    const double beyond = surface.behind(at);
    s.reached =
      on_surface[v]
        ? beyond < 0 || (catching_up && on_crack && beyond < 0.25 * typical_edge)
        : (surface.behind(x) < 0 && surface.ahead_of_start(x) >= -start_reach)
            || swept[v] == stroke;
    s.sweep_on_plane = s.on_plane;
    s.sweep_reached  = s.reached;
    return s;
  }


  void
  Cutter::analyse(const SweepSurface &surface)
  {
    const double eps = parameters.snap_fraction;
    // The closure is a fixed point: each pass adds the cells that must be split with
    // the set (around reached crossings, the stars of vertices joining the crack, the
    // neighbours across front faces), at least one per pass, so it ends within the
    // cells next to the swept surface. The number of passes grows with the cells
    // along the front; any fixed cap postpones every sweep of a fine enough mesh.
    while (true)
    {
      ++analysis_stamp;
      verts.clear();
      edge_list.clear();
      front_rest.clear();
      for (const unsigned int t : affected)
      {
        const mesh::Tet &tet = mesh.tet(t);
        for (const unsigned int v : tet)
          if (vertex_scratch[v].stamp != analysis_stamp)
          {
            vertex_data(v, surface);
            verts.push_back(v);
          }
        for (const unsigned int e : mesh.tet_edges(t))
          if (edge_scratch[e].stamp != analysis_stamp)
          {
            edge_scratch[e].stamp    = analysis_stamp;
            edge_scratch[e].crossing = false;
            edge_scratch[e].reached  = false;
            edge_list.push_back(e);
          }
      }
      const auto &edges = mesh.get_edges();
      // Snapping: a vertex on the surface (exactly, kept from earlier sweeps of the
      // stroke, or snapped by a crossing close to it) has no cut edge.
      for (const unsigned int e : edge_list)
      {
        VertexScratch &a = vertex_scratch[edges[e][0]], &b = vertex_scratch[edges[e][1]];
        if (!a.on_plane && !b.on_plane && a.d * b.d < 0)
        {
          const EdgeSnap snap = snap_edge_parameter(a.d / (a.d - b.d), eps);
          if (snap == EdgeSnap::first_vertex)
            a.on_plane = true;
          else if (snap == EdgeSnap::second_vertex)
            b.on_plane = true;
        }
      }
      // Vertices on the surface joined by edges in the surface are reached together
      // (the front never crosses such an edge): the whole connected patch, followed
      // beyond the affected cells through the vertex stars, waits until all of it
      // has been swept. Its vertices outside the affected set join it when reached.
      group_extra.clear();
      const auto root = [&](unsigned int v)
      {
        while (vertex_scratch[v].parent != v)
          v = vertex_scratch[v].parent = vertex_scratch[vertex_scratch[v].parent].parent;
        return v;
      };
      // Inside the affected cells: the edges in the surface.
      for (const unsigned int e : edge_list)
        if (vertex_scratch[edges[e][0]].on_plane && vertex_scratch[edges[e][1]].on_plane)
          vertex_scratch[root(edges[e][0])].parent = root(edges[e][1]);
      // Beyond them, from the fresh vertices on the plane (not yet on the crack: the
      // crack already made is reached and need not be walked) through their stars.
      group.clear();
      for (const unsigned int v : verts)
        if (vertex_scratch[v].on_plane && !on_surface[v])
          group.push_back(v);
      for (std::size_t q = 0; q < group.size(); ++q)
      {
        const unsigned int u = group[q];
        for (const unsigned int t : mesh.tets_of_vertex(u))
        {
          if (tet_mark[t] == affected_stamp)
            continue;
          for (const unsigned int w : mesh.tet(t))
          {
            if (w == u || on_surface[w])
              continue;
            const bool     is_new = vertex_scratch[w].stamp != analysis_stamp;
            VertexScratch &s      = vertex_data(w, surface);
            if (!s.on_plane)
              continue;
            if (is_new)
            {
              group_extra.push_back(w);
              group.push_back(w);
            }
            vertex_scratch[root(w)].parent = root(u);
          }
        }
      }
      for (const unsigned int v : verts)
        vertex_scratch[v].group_reached = true;
      for (const unsigned int v : group_extra)
        vertex_scratch[v].group_reached = true;
      const auto gather = [&](const unsigned int v)
      {
        VertexScratch &s = vertex_scratch[v];
        if (!s.on_plane)
          return;
        if (s.reached && !on_surface[v])
        {
          // Where it was first swept: later sweeps judge it there (vertex_data()).
          if (swept[v] != stroke)
            joined_at[v] = position(v);
          swept[v] = stroke;
        }
        if (!s.reached)
          vertex_scratch[root(v)].group_reached = false;
      };
      for (const unsigned int v : verts)
        gather(v);
      for (const unsigned int v : group_extra)
        gather(v);
      for (const unsigned int v : verts)
        if (vertex_scratch[v].on_plane)
          vertex_scratch[v].reached = vertex_scratch[root(v)].group_reached;
      for (const unsigned int v : group_extra)
        vertex_scratch[v].reached = vertex_scratch[root(v)].group_reached;
      for (const unsigned int v : verts)
      {
        VertexScratch &s = vertex_scratch[v];
        s.side           = s.on_plane && s.reached ? 0 : (s.d >= 0 ? 1 : -1);
        // A vertex of the crack that this stroke's plane reaches only now (where the
        // path crosses its own crack): its star must be re-split, so that the faces
        // in the plane through it open.
        if (s.on_plane && on_surface[v] && !s.reached)
          crossing_pending[v] = stroke;
      }
      for (const unsigned int v : group_extra)
      {
        VertexScratch &s = vertex_scratch[v];
        s.side           = s.on_plane && s.reached ? 0 : (s.d >= 0 ? 1 : -1);
      }
      // Crossings of the surface; the reached ones are cut.
      for (const unsigned int e : edge_list)
      {
        EdgeScratch         &es = edge_scratch[e];
        const VertexScratch &a  = vertex_scratch[edges[e][0]],
                            &b  = vertex_scratch[edges[e][1]];
        if (a.on_plane || b.on_plane || !(a.d * b.d < 0))
          continue;
        es.t          = a.d / (a.d - b.d);
        const Point p = lerp(position(edges[e][0]), position(edges[e][1]), es.t);
        if (surface.ahead_of_start(p) < -start_reach
            && !std::binary_search(front_edge_ids.begin(), front_edge_ids.end(), e))
          continue;
        es.crossing = true;
        es.reached  = surface.behind(p) < 0;
      }
      // Front points, once per face, from the face's two section corners.
      for (const unsigned int t : affected)
      {
        // A front point lies between a reached and an unreached corner (a vertex on
        // the plane or a crossing): a cell without both, as most cells behind the
        // front, has none on any face.
        bool any_reached = false, any_unreached = false;
        for (const unsigned int v : mesh.tet(t))
          if (vertex_scratch[v].on_plane)
            (vertex_scratch[v].reached ? any_reached : any_unreached) = true;
        for (const unsigned int e : mesh.tet_edges(t))
          if (edge_scratch[e].crossing)
            (edge_scratch[e].reached ? any_reached : any_unreached) = true;
        for (unsigned int f = 0; f < 4; ++f)
        {
          FaceScratch &fs = face_scratch[4 * t + f];
          if (fs.stamp == analysis_stamp)
            continue;
          fs.stamp = analysis_stamp;
          fs.front = FaceScratch::no_front;
          if (any_reached && any_unreached)
            compute_front_point(t, f, surface, fs);
          // The face seen from the neighbour gets the same front point.
          const unsigned int n = mesh.neighbor(t, f);
          if (n != mesh::invalid_index)
            for (unsigned int g = 0; g < 4; ++g)
              if (mesh.neighbor(n, g) == t)
              {
                face_scratch[4 * n + g].stamp = fs.stamp;
                face_scratch[4 * n + g].front = fs.front;
              }
        }
      }
      // Closure: everything that must be split alike has to be in the set.
      missing.clear();
      ++star_stamp;
      for (const unsigned int e : edge_list)
        if (edge_scratch[e].reached)
        {
          // Usually every cell around the edge is in the set already: the smaller
          // star of the two ends tells. Otherwise the cells are listed in the mesh's
          // order, as before.
          const unsigned int a = edges[e][0], b = edges[e][1];
          bool               outside = false;
          mesh.visit_tets_with_edge(a,
                                    b,
                                    [&](const unsigned int n, unsigned int)
                                    {
                                      outside = tet_mark[n] != affected_stamp;
                                      return outside;
                                    });
          if (!outside)
            continue;
          around.clear();
          mesh.tets_around_edge(a, b, around);
          for (const unsigned int n : around)
            if (tet_mark[n] != affected_stamp)
              missing.push_back(n);
        }
      // A vertex joining the crack needs its whole star (its copies are decided on
      // it): a vertex newly on the surface, one of a cell that is cut now, or one of
      // the crack that the plane reaches only now (see crossing_pending). Old
      // crack vertices elsewhere stay as they are, so the set does not spread along
      // the whole crack.
      for (const unsigned int t : affected)
      {
        const bool is_cut = tet_is_cut(t);
        for (const unsigned int v : mesh.tet(t))
          if (vertex_scratch[v].side == 0
              && (is_cut || !on_surface[v] || crossing_pending[v] == stroke))
            vertex_scratch[v].star_stamp = star_stamp;
      }
      for (const unsigned int v : group_extra)
        if (vertex_scratch[v].side == 0 && !on_surface[v])
          vertex_scratch[v].star_stamp = star_stamp;
      for (const unsigned int v : verts)
        if (vertex_scratch[v].star_stamp == star_stamp)
          for (const unsigned int n : mesh.tets_of_vertex(v))
            if (tet_mark[n] != affected_stamp)
              missing.push_back(n);
      for (const unsigned int v : group_extra)
        if (vertex_scratch[v].star_stamp == star_stamp)
          for (const unsigned int n : mesh.tets_of_vertex(v))
            if (tet_mark[n] != affected_stamp)
              missing.push_back(n);
      for (const unsigned int t : affected)
        for (unsigned int f = 0; f < 4; ++f)
          if (face_scratch[4 * t + f].has_front())
          {
            const unsigned int n = mesh.neighbor(t, f);
            if (n != mesh::invalid_index && tet_mark[n] != affected_stamp)
              missing.push_back(n);
          }
      if (missing.empty())
        return;
      for (const unsigned int n : missing)
        join_affected(n);
    }
  }


  void
  Cutter::join_affected(const unsigned int t)
  {
    if (tet_mark[t] != affected_stamp)
    {
      tet_mark[t] = affected_stamp;
      affected.push_back(t);
    }
  }


  bool
  Cutter::tet_is_cut(const unsigned int t) const
  {
    for (const unsigned int e : mesh.tet_edges(t))
      if (edge_scratch[e].reached)
        return true;
    for (unsigned int f = 0; f < 4; ++f)
      if (face_scratch[4 * t + f].has_front())
        return true;
    return false;
  }


  void
  Cutter::compute_front_point(const unsigned int  t,
                              const unsigned int  f,
                              const SweepSurface &surface,
                              FaceScratch        &fs)
  {
    const mesh::Tet                  &tet = mesh.tet(t);
    const auto                       &fv  = mesh::TetMesh::face_vertices[f];
    const std::array<unsigned int, 3> v{{tet[fv[0]], tet[fv[1]], tet[fv[2]]}};
    const auto                       &edge_ids = mesh.tet_edges(t);
    // Most faces have no front point: front_point_on_face() wants a segment (two
    // corners) between a reached and an unreached corner, not two vertex corners.
    // Counting the corners first spares those faces the interpolations.
    {
      unsigned int n = 0, n_vertex = 0, n_reached = 0;
      for (unsigned int k = 0; k < 3; ++k)
      {
        const VertexScratch &vs = vertex_scratch[v[k]];
        if (vs.on_plane)
        {
          ++n;
          ++n_vertex;
          n_reached += vs.reached ? 1 : 0;
        }
      }
      for (unsigned int k = 0; k < 3 && n < 3; ++k)
      {
        const EdgeScratch &es = edge_scratch[edge_ids[face_edges[f][k]]];
        if (es.crossing)
        {
          ++n;
          n_reached += es.reached ? 1 : 0;
        }
      }
      if (n != 2 || n_reached != 1 || n_vertex == 2)
        return;
    }
    std::array<SectionCorner, 3> corners;
    unsigned int                 n_corners = 0, vertex_corners = 0;
    for (unsigned int k = 0; k < 3; ++k)
      if (vertex_scratch[v[k]].on_plane)
      {
        corners[n_corners++] = {mesh.vertex(v[k]),
                                position(v[k]),
                                vertex_scratch[v[k]].reached};
        ++vertex_corners;
      }
    for (unsigned int k = 0; k < 3 && n_corners < 3; ++k)
    {
      const unsigned int a  = std::min(v[k], v[(k + 1) % 3]),
                         b  = std::max(v[k], v[(k + 1) % 3]);
      const EdgeScratch &es = edge_scratch[edge_ids[face_edges[f][k]]];
      if (!es.crossing)
        continue;
      corners[n_corners++] = {lerp(mesh.vertex(a), mesh.vertex(b), es.t),
                              lerp(position(a), position(b), es.t),
                              es.reached};
    }
    Point rest, now;
    if (front_point_on_face(
          corners.data(),
          n_corners,
          vertex_corners,
          [&](const Point &x) { return surface.behind(x); },
          parameters.snap_fraction,
          rest,
          now))
    {
      fs.front = static_cast<unsigned int>(front_rest.size());
      front_rest.push_back(rest);
    }
  }


  void
  Cutter::apply(const Blade &end, CutStepStatistics &statistics)
  {
    // Contributions of the tetrahedra that go, straight from the particles and from
    // the springs of their edges (by edge id, before the mesh update moves the ids;
    // a spring whose edge dies is retired with it). Every spring gets these terms
    // first and those of the new tetrahedra after, in the order of the cells.
    physics::SpringSet &springs = system.springs;
    // The edges this sweep's plane crosses ahead of its front, by their ends (the
    // update renumbers edges): the next sweep cuts them wherever the plane meets them.
    front_edges.clear();
    for (const unsigned int e : edge_list)
      if (edge_scratch[e].crossing && !edge_scratch[e].reached)
        front_edges.push_back(mesh.get_edges()[e]);
    touched_vertices.clear();
    double integral_delta = 0;
    // A constant density and Young's modulus (the common case) need no Function call
    // and one volume per cell instead of two; the masses and stiffness factors are the
    // same to the last bit.
    struct CellTerms
    {
      std::array<double, 4> mass;
      double                stiffness_factor;
    };
    const auto cell_terms = [&](const unsigned int t) -> CellTerms
    {
      if (constant_density_mass && constant_youngs_modulus)
      {
        const double volume = mesh.volume(t);
        return {(*constant_density_mass)(volume), *constant_youngs_modulus * volume};
      }
      return {constant_density_mass ? (*constant_density_mass)(mesh.volume(t))
                                    : physics::tet_mass_contributions(mesh, t, density),
              physics::tet_stiffness_factor(mesh, t, youngs_modulus)};
    };
    for (const unsigned int r : removed)
    {
      const CellTerms              terms = cell_terms(r);
      const std::array<double, 4> &m     = terms.mass;
      for (unsigned int i = 0; i < 4; ++i)
      {
        system.mass[mesh.tet(r)[i]] -= m[i];
        touched_vertices.push_back(mesh.tet(r)[i]);
        integral_delta -= m[i];
      }
      const double f = -terms.stiffness_factor;
      for (const unsigned int e : mesh.tet_edges(r))
      {
        springs.stiffness[e] += f / (springs.rest_length[e] * springs.rest_length[e]);
        changed_springs.push_back(e);
      }
    }

    lap(statistics.physics_seconds);

    // New points, merged across tetrahedra through the edge and face they lie on (one
    // particle per edge and side, per face); state interpolated from the parent (the
    // same affine map at rest and deformed).
    ++merge_stamp;
    children.clear();
    child_cut_faces.clear();
    face_ids.clear();
    // The record of this sweep for the Multi-Triangulation (set_recorder()).
    CutRecord *record = recorder ? &recorder->emplace_back() : nullptr;
    if (record)
    {
      record->cuts = cuts;
      child_origin.clear();
    }
    const auto new_particle = [&](const Point &rest, const unsigned int parent)
    {
      const mesh::Tet &tet = mesh.tet(parent);
      const auto       l   = rest_barycentric(mesh, parent, rest);
      Point            x{{0, 0, 0}}, v{{0, 0, 0}};
      for (unsigned int i = 0; i < 4; ++i)
        for (unsigned int c = 0; c < 3; ++c)
        {
          x[c] += l[i] * system.position[3 * tet[i] + c];
          v[c] += l[i] * system.velocity[3 * tet[i] + c];
        }
      const unsigned int id = mesh.add_vertex(rest);
      system.add_particle(rest, x, v);
      ++statistics.new_particles;
      return id;
    };
    for (std::size_t k = 0; k < cuts.size(); ++k)
    {
      const TetCut      &c        = cuts[k];
      const SplitResult &r        = results[k];
      const unsigned int parent   = removed[k];
      unsigned int       interior = mesh::invalid_index;
      if (r.kind != CutKind::none && r.kind != CutKind::touch)
      {
        statistics.cut_tets += 1;
        statistics.created_tets += r.n_children;
      }
      // The parent's boundary ids, looked up once for all its children (most
      // parents are inside the body and have none).
      std::array<unsigned int, 4> parent_ids;
      unsigned int                parent_boundary = 0;
      for (unsigned int f = 0; f < 4; ++f)
      {
        parent_ids[f] = mesh.boundary_id(parent, f);
        if (parent_ids[f] != mesh::invalid_index)
          parent_boundary |= 1u << f;
      }
      for (unsigned int i = 0; i < r.n_children; ++i)
      {
        const Child &child = r.children[i];
        mesh::Tet    t;
        for (unsigned int j = 0; j < 4; ++j)
        {
          const NodeRef &n = child.nodes[j];
          unsigned int  *slot;
          switch (n.kind)
          {
            case NodeKind::vertex:
              t[j] = static_cast<unsigned int>(c.vertex_ids[n.index]);
              continue;
            case NodeKind::edge_point:
            {
              EdgeScratch &es = edge_scratch[mesh.tet_edges(parent)[n.index]];
              if (es.point_stamp != merge_stamp)
              {
                es.point_stamp = merge_stamp;
                es.point       = {
                        {mesh::invalid_index, mesh::invalid_index, mesh::invalid_index}};
              }
              // The side of the copy this child uses (point_key()'s side of an edge
              // point).
              slot = &es.point[n.side + 1];
              break;
            }
            case NodeKind::face_point:
            {
              FaceScratch &fs = face_scratch[4 * parent + n.index];
              if (fs.point_stamp != merge_stamp)
              {
                fs.point_stamp = merge_stamp;
                fs.point       = mesh::invalid_index;
              }
              slot = &fs.point;
              break;
            }
            default:
              slot = &interior;
              break;
          }
          if (*slot == mesh::invalid_index)
          {
            const Point p = n.kind == NodeKind::edge_point   ? r.edge_points[n.index]
                            : n.kind == NodeKind::face_point ? r.face_points[n.index]
                                                             : r.interior_point;
            *slot         = new_particle(p, parent);
            if (record)
            {
              CutRecord::NewPoint point{*slot, n.kind, 0, {}, p};
              if (n.kind == NodeKind::interior_point)
              {
                for (unsigned int m = 0; m < 4; ++m)
                  point.ids[m] = static_cast<unsigned int>(c.vertex_ids[m]);
                std::sort(point.ids.begin(), point.ids.end());
              }
              else
              {
                const auto key = point_key(c.vertex_ids, n, parent);
                point.side     = key.side;
                for (unsigned int m = 0; m < 3; ++m)
                  point.ids[m] = static_cast<unsigned int>(key.ids[m]);
              }
              record->new_points.push_back(point);
            }
            if (n.kind == NodeKind::face_point)
            {
              // The same point for the cell across the face.
              const unsigned int nb = mesh.neighbor(parent, n.index);
              if (nb != mesh::invalid_index)
                for (unsigned int g = 0; g < 4; ++g)
                  if (mesh.neighbor(nb, g) == parent)
                  {
                    face_scratch[4 * nb + g].point_stamp = merge_stamp;
                    face_scratch[4 * nb + g].point       = *slot;
                  }
            }
            if (n.kind != NodeKind::interior_point)
              mark_on_surface(*slot);
          }
          t[j] = *slot;
        }
        std::array<unsigned int, 4> fid{{0, 0, 0, 0}};
        for (unsigned int j = 0; j < 4; ++j)
        {
          if (child.cut_faces & (1u << j))
          {
            fid[j] = cut_boundary_id;
            continue;
          }
          // A face on a parent's boundary face keeps its boundary id: the parent's
          // faces that all three of its nodes lie on (the last such face wins).
          if (parent_boundary == 0)
            continue;
          unsigned int on = parent_boundary;
          for (unsigned int m = 0; m < 4; ++m)
            if (m != j)
              on &= parent_faces_of_node(child.nodes[m]);
          for (unsigned int f = 0; f < 4; ++f)
            if (on & (1u << f))
              fid[j] = parent_ids[f];
        }
        children.push_back(t);
        if (record)
          child_origin.push_back({{static_cast<unsigned int>(k), i}});
        child_cut_faces.push_back(child.cut_faces);
        face_ids.push_back(fid);
        child_partial.push_back(r.kind == CutKind::partial);
      }
    }
    // Vertices on the cut: one copy per group of their children connected through
    // faces not on the cut, so that the two sides separate where the crack is open
    // and stay joined at the crack tip.
    incidences.clear();
    for (std::size_t k = 0; k < children.size(); ++k)
      for (const unsigned int v : children[k])
        if (v < vertex_scratch.size() && vertex_scratch[v].stamp == analysis_stamp
            && vertex_scratch[v].star_stamp == star_stamp)
          incidences.push_back({{v, static_cast<unsigned int>(k)}});
    std::sort(incidences.begin(), incidences.end());
    for (std::size_t b = 0; b < incidences.size();)
    {
      const unsigned int v = incidences[b][0];
      std::size_t        e = b;
      star.clear();
      while (e < incidences.size() && incidences[e][0] == v)
      {
        const mesh::Tet &c = children[incidences[e][1]];
        star.push_back({{{c[0], c[1], c[2], c[3]}}, child_cut_faces[incidences[e][1]]});
        ++e;
      }
      const unsigned int n_groups = separate_star(v, star, star_group);
      copy_ids.assign(n_groups, v);
      for (unsigned int g = 1; g < n_groups; ++g)
      {
        const unsigned int copy = mesh.add_vertex(mesh.vertex(v));
        system.add_particle(mesh.vertex(v),
                            position(v),
                            {{system.velocity[3 * v],
                              system.velocity[3 * v + 1],
                              system.velocity[3 * v + 2]}});
        // A copy keeps its original's constraint (the scene extends its particle
        // lists from `copied_particles`).
        system.free[copy] = system.free[v];
        statistics.copied_particles.push_back({{v, copy}});
        mark_on_surface(copy);
        ++statistics.new_particles;
        copy_ids[g] = copy;
        if (record)
          record->new_points.push_back(
            {copy, NodeKind::vertex, 0, {{v, 0, 0, 0}}, mesh.vertex(v)});
      }
      for (std::size_t i = 0; i < star.size(); ++i)
      {
        const unsigned int child = incidences[b + i][1];
        for (unsigned int m = 0; m < 4; ++m)
          if (children[child][m] == v)
          {
            children[child][m] = copy_ids[star_group[i]];
            if (record)
              record->vertex_choices.push_back(
                {child_origin[child][0],
                 static_cast<std::uint8_t>(child_origin[child][1]),
                 static_cast<std::uint8_t>(m),
                 copy_ids[star_group[i]]});
          }
      }
      mark_on_surface(v);
      b = e;
    }

    lap(statistics.children_seconds);

    // The mesh, locally.
    mesh.replace_tets(removed, children, face_ids, added_ids, edge_update);
    lap(statistics.mesh_seconds);

    // Springs follow the edges: appended, moved into retired slots, restiffened.
    const auto &edges = mesh.get_edges();
    for (unsigned int i = 0; i < edge_update.n_added; ++i)
    {
      const unsigned int e = static_cast<unsigned int>(springs.size());
      changed_springs.push_back(e);
      springs.push_back(edges[e][0],
                        edges[e][1],
                        0.0,
                        norm(sub(mesh.vertex(edges[e][1]), mesh.vertex(edges[e][0]))));
    }
    for (const auto &[to, from] : edge_update.moves)
    {
      // The mesh copied its last edge `from` into slot `to`: so do the springs.
      Assert(from + 1 == springs.size(), dealii::ExcInternalError());
      changed_springs.push_back(to);
      springs.retire(to);
    }
    prepare_scratch();
    for (std::size_t k = 0; k < added_ids.size(); ++k)
    {
      const unsigned int           t     = added_ids[k];
      const CellTerms              terms = cell_terms(t);
      const std::array<double, 4> &m     = terms.mass;
      for (unsigned int i = 0; i < 4; ++i)
      {
        system.mass[mesh.tet(t)[i]] += m[i];
        touched_vertices.push_back(mesh.tet(t)[i]);
        integral_delta += m[i];
      }
      const double f = terms.stiffness_factor;
      for (const unsigned int e : mesh.tet_edges(t))
      {
        springs.stiffness[e] += f / (springs.rest_length[e] * springs.rest_length[e]);
        changed_springs.push_back(e);
      }
      for (unsigned int f2 = 0; f2 < 4; ++f2)
        if (mesh.neighbor(t, f2) == mesh::invalid_index)
          tree.add_face(mesh, t, f2);
      // Children of a partial split are not split partially again in this stroke.
      partial_child[t] = child_partial[k] ? stroke : 0;
    }
    child_partial.clear();
    for (const unsigned int v : verts)
      if (vertex_scratch[v].star_stamp == star_stamp && v < crossing_pending.size())
        crossing_pending[v] = 0;
    // A vertex that lost all its cells cannot happen (copies take over whole stars),
    // but a mass that rounding left a hair below zero would be nonsense: clamp. A mass
    // further below zero is a particle that gave mass to its neighbours
    // (physics::MassBalancer) and lost cells since: the balancer raises it again, and
    // clamping it would add mass.
    const double rounding = 1e-12 * std::abs(integral_of_density);
    for (const unsigned int v : touched_vertices)
      if (system.mass[v] < 0 && system.mass[v] > -rounding)
        system.mass[v] = 0;
    integral_of_density += integral_delta;

    // The active cells: the new ones the blade is in.
    std::sort(removed.begin(), removed.end());
    active.erase(std::remove_if(active.begin(),
                                active.end(),
                                [&](unsigned int t) {
                                  return std::binary_search(removed.begin(),
                                                            removed.end(),
                                                            t);
                                }),
                 active.end());
    // A new cell whose box is farther from the blade's than a tenth of its own size
    // does not contain the blade, and the exact test's rounding moves its answer by
    // far less than that (blade_in_tet() ignores faces within 1e-14 rad of the
    // blade's direction): only the cells near the blade are tested.
    Box blade_box;
    blade_box.extend(end.tail);
    blade_box.extend(end.head);
    for (const unsigned int t : added_ids)
    {
      Box cell;
      for (const unsigned int v : mesh.tet(t))
        cell.extend(position(v));
      cell.inflate(0.1 * cell.size());
      if (cell.overlaps(blade_box) && blade_in_tet(t, end))
        active.push_back(t);
    }
    statistics.changed = true;
    lap(statistics.physics_seconds);
  }


  void
  Cutter::lap(double &phase)
  {
    const auto now = Clock::now();
    phase += std::chrono::duration<double>(now - lap_start).count();
    lap_start = now;
  }


  void
  Cutter::adopt_crack(const std::vector<unsigned int> &crack)
  {
    for (const unsigned int v : crack)
    {
      AssertIndexRange(v, mesh.n_vertices());
      mark_on_surface(v);
    }
  }


  void
  Cutter::mark_on_surface(const unsigned int v)
  {
    // Grown by a few hundred entries at a time: the children of a sweep mark their
    // new particles one by one (entries past the mesh's vertices stay 0).
    if (v >= on_surface.size())
      on_surface.resize(std::size_t(mesh.n_vertices()) + 256, 0);
    if (!on_surface[v])
    {
      if (v >= joined_at.size())
        joined_at.resize(std::size_t(mesh.n_vertices()) + 256);
      joined_at[v]  = position(v);
      on_surface[v] = 1;
      on_surface_list.push_back(v);
    }
  }
} // namespace lacerta::cut
