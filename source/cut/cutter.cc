#include <lacerta/base/archive.h>
#include <lacerta/base/exceptions.h>
#include <lacerta/cut/cutter.h>
#include <lacerta/cut/predicates.h>
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

    /// Two sweeps are the same part of the swept surface, for the sides of the
    /// vertices next to it, when their normals are less than 45 degrees apart: the
    /// blade cutting on along a path that bends gradually. A sharper turn (a corner,
    /// a path that comes back across its own cut) is another part, on which the
    /// vertices' sides are decided anew.
    constexpr double same_part_cosine = 0.7071067811865476;

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
    prm.declare_entry(
      "Snap fraction",
      "0.05",
      dealii::Patterns::Double(0.001, 0.45),
      "A cut point closer to an end of its edge than this fraction of the "
      "size of the cells around the edge (their longest edge at rest) "
      "snaps onto that end (doc/cutting.md, step 5): no sliver is "
      "created, and a layer an earlier cut left thin is not cut thinner.");
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
      , topology(mesh_in, system_in, density_in, youngs_modulus_in)
      , integral_of_density(integral)
      , parameters(parameters_in)
      , current(initial)
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
    on_surface.reserve(room(mesh.n_vertices()));
    crossings_at.reserve(room(mesh.n_vertices()));
    separate_mark.reserve(room(mesh.n_vertices()));
    edge_scratch.reserve(room(mesh.n_edges()));
    edge_stamp.reserve(room(mesh.n_edges()));
    tet_mark.reserve(room(mesh.n_tets()));
    tet_stamp.reserve(room(mesh.n_tets()));
    in_star.reserve(room(mesh.n_tets()));
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
    // The crossings decided in the stroke and not applied (the surface ended inside
    // their cells: a partial stroke) are forgotten: the next stroke decides anew.
    for (auto it = crossings.begin(); it != crossings.end();)
      it = forget_crossing(it);
    // The vertices' sides belong to this stroke.
    ++stroke;
    part.normal = Point{};
  }


  void
  Cutter::follow_part(const Point &normal)
  {
    // A zero normal (a new stroke) is never the same part.
    if (dot(part.normal, normal) <= same_part_cosine)
      part.triangles.clear();
    part.normal = normal;
  }


  void
  Cutter::keep_part_sweep(const std::array<std::array<Point, 3>, 2> &swept_triangles)
  {
    if (part.triangles.size() >= 2 * std::size_t(kept_part_sweeps))
      part.triangles.erase(part.triangles.begin(), part.triangles.begin() + 2);
    part.triangles.insert(part.triangles.end(),
                          swept_triangles.begin(),
                          swept_triangles.end());
  }


  bool
  Cutter::part_reaches(const unsigned int                         v,
                       const double                               distance,
                       const std::array<std::array<Point, 3>, 2> &swept_triangles) const
  {
    // The middle of the blade before and after the sweep (swept_triangles[0] is
    // {from.tail, from.head, to.tail}, swept_triangles[1] {to.tail, from.head, to.head}).
    const Point x    = position(v);
    const Point from = scale(0.5, add(swept_triangles[0][0], swept_triangles[0][1]));
    const Point motion =
      sub(scale(0.5, add(swept_triangles[1][0], swept_triangles[1][2])), from);
    if (dot(sub(x, from), motion) >= -distance * norm(motion))
      return true;
    const auto near = [&](const std::array<Point, 3> &t)
    { return mesh::point_triangle_distance(x, t[0], t[1], t[2]) <= distance; };
    return std::any_of(swept_triangles.begin(), swept_triangles.end(), near)
           || std::any_of(part.triangles.begin(), part.triangles.end(), near);
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
    const double sweeps = std::ceil(advance / (parameters.max_advance * h));
    if (!(sweeps <= max_sweeps_per_motion))
      throw_error("Cutter: the blade moves ",
                  advance,
                  " m in one motion, which needs ",
                  sweeps,
                  " sweeps of at most ",
                  parameters.max_advance * h,
                  " m ('Cut/Maximum advance' times the element size around the blade, ",
                  h,
                  " m), more than ",
                  max_sweeps_per_motion,
                  ": the tool's path jumps, or the tissue around the blade has blown "
                  "up.");
    const unsigned int n     = std::max(1u, static_cast<unsigned int>(sweeps));
    const Blade        start = current;
    // The tissue moves between blade motions: a crossing just ahead of where the last
    // motion ended can be carried behind where this one starts, and no sweep would
    // meet it. The first sweep therefore starts behind the blade by as far as the
    // tissue around it moved since (the overlap is harmless: a crossing seen twice
    // the same way is one crossing).
    Blade  from = start;
    double back = 0;
    for (const auto &[v, x] : blade_cell_positions)
      if (v < mesh.n_vertices())
        back = std::max(back, norm(sub(position(v), x)));
    const Point motion =
      sub(scale(0.5, add(next.tail, next.head)), scale(0.5, add(start.tail, start.head)));
    if (back > 0 && norm(motion) > 0)
    {
      const Point shift = scale(back / norm(motion), motion);
      from.tail         = sub(from.tail, shift);
      from.head         = sub(from.head, shift);
    }
    for (unsigned int k = 1; k <= n; ++k)
    {
      const double s  = double(k) / n;
      const Blade  to = {lerp(start.tail, next.tail, s), lerp(start.head, next.head, s)};
      sweep(from, to, statistics);
      from = to;
    }
    current = next;
    // The blade has left the tissue (it is in no cell): the stroke is over.
    if (active.empty())
      end_stroke();
    blade_cell_positions.clear();
    for (const unsigned int t : active)
      for (const unsigned int v : mesh.tet(t))
        blade_cell_positions.push_back({v, position(v)});
    if (statistics.changed)
    {
      const auto t0 = Clock::now();
      topology.notify_force_model();
      statistics.reinit_seconds =
        std::chrono::duration<double>(Clock::now() - t0).count();
    }
    return statistics;
  }


  void
  Cutter::sweep(const Blade &from, const Blade &to, CutStepStatistics &statistics)
  {
    ++statistics.sweeps;
    const std::array<std::array<Point, 3>, 2> swept_triangles = {
      {{{from.tail, from.head, to.tail}}, {{to.tail, from.head, to.head}}}};
    const auto t_search = Clock::now();
    find_tets_to_cut(swept_triangles, to);
    statistics.search_seconds +=
      std::chrono::duration<double>(Clock::now() - t_search).count();
    active.swap(next_active);
    if (candidates.empty())
    {
      // Out of the tissue: the stroke is over.
      end_stroke();
      return;
    }
    const auto t_start = Clock::now();
    lap_start          = t_start;
    prepare_scratch();
    record_crossings(swept_triangles);
    select_cells();
    make_cuts();
    lap(statistics.analysis_seconds);
    if (!removed.empty())
    {
      results.resize(cuts.size());
      for (std::size_t k = 0; k < cuts.size(); ++k)
        split_tetrahedron(cuts[k], results[k], parameters.snap_fraction);
      lap(statistics.split_seconds);
      forget_applied_crossings();
      apply(to, statistics);
    }
    statistics.update_seconds +=
      std::chrono::duration<double>(Clock::now() - t_start).count();
  }


  void
  Cutter::prepare_scratch()
  {
    edge_scratch.resize(mesh.n_edges());
    tet_mark.resize(mesh.n_tets(), 0);
    in_star.resize(mesh.n_tets(), 0);
    if (on_surface.size() < mesh.n_vertices())
      on_surface.resize(mesh.n_vertices(), 0);
    if (separate_mark.size() < mesh.n_vertices())
      separate_mark.resize(mesh.n_vertices(), 0);
    fresh_mark.resize(std::max(fresh_mark.size(), on_surface.size()), 0);
    crossings_at.resize(mesh.n_vertices(), 0);
  }


  void
  Cutter::record_crossings(const std::array<std::array<Point, 3>, 2> &swept_triangles)
  {
    const double eps = parameters.snap_fraction;
    new_crossings.clear();
    new_on_surface.clear();
    // The orientation of this part of the swept surface.
    Point normal = cross(sub(swept_triangles[0][1], swept_triangles[0][0]),
                         sub(swept_triangles[0][2], swept_triangles[0][0]));
    if (!(norm(normal) > 0))
      normal = cross(sub(swept_triangles[1][1], swept_triangles[1][0]),
                     sub(swept_triangles[1][2], swept_triangles[1][0]));
    if (!(norm(normal) > 0))
      return; // the blade moved along itself: it sweeps no surface
    normal         = normalized(normal);
    sweep_triangle = swept_triangles[0];
    follow_part(normal);
    ++analysis_stamp;
    for (const unsigned int t : candidates)
      for (unsigned int e = 0; e < 6; ++e)
      {
        EdgeScratch &es = edge_scratch[mesh.tet_edges(t)[e]];
        if (es.stamp == analysis_stamp)
          continue;
        es.stamp       = analysis_stamp;
        unsigned int a = mesh.tet(t)[tet_edge_vertices[e][0]];
        unsigned int b = mesh.tet(t)[tet_edge_vertices[e][1]];
        if (b < a)
          std::swap(a, b);
        // An edge with an end on the cut is never cut: the cut passes through the end.
        if (on_surface[a] || on_surface[b])
          continue;
        std::array<double, 2> distance{};
        const Crossing crossing = edge_crossing(a, b, swept_triangles, normal, distance);
        if (crossing.side == 0)
          continue;
        // The ends' sides are decided for this part of the surface.
        keep_side(a, crossing.side, normal);
        keep_side(b, std::int8_t(-crossing.side), normal);
        const std::uint64_t key = edge_key(a, b);
        const auto          it  = crossings.find(key);
        if (it != crossings.end())
        {
          // Crossed again in the same direction, or at the same place (within ε of
          // the edge): the same crossing, seen by two sweeps (their triangles share
          // lines, and the tissue moves between blade motions) or by the blade going
          // back over its cut; the first decision stands. In the opposite direction
          // elsewhere along the edge: the edge went into the swept surface and out
          // again (through a corner of the path, or a path that comes back), so its
          // ends lie on one side: no crossing.
          if (it->second.side != crossing.side
              && std::abs(it->second.t - crossing.t) >= eps)
          {
            forget_crossing(it);
            new_crossings.push_back(key);
          }
          continue;
        }
        // Snapping, once: an end closer to the swept surface than ε times the size of
        // the cells around the edge (their longest edge) is put on the cut (the edge
        // is then not cut), unless a crossing of another of its edges was decided
        // before. Then no cut point lies within ε of a cell's size from an end: an
        // edge nearly in the surface (a blade along a face) does not shave a sliver
        // off it, and a short edge in a fat cell (left by an earlier cut) is not cut
        // again next to its end, where the spring's stiffness E V / |e|² would grow
        // like the inverse square of the distance while the cell's volume does not.
        // Only onto a part of the surface that reaches the end: an end behind the
        // corner where this part started is not on it, however close to its plane
        // (the blade never swept there in this direction; put on the cut, its faces
        // and the previous part's cut points enclosed fragments).
        const double relative =
          eps
          * std::max(1.0,
                     cell_size_around(a, b) / norm(sub(mesh.vertex(b), mesh.vertex(a))));
        const double reach_of_snap = relative * norm(sub(position(b), position(a)));
        const bool   snap_a        = distance[0] < relative
                            && part_reaches(a, reach_of_snap, swept_triangles)
                            && may_snap(a);
        const bool snap_b = distance[1] < relative
                            && part_reaches(b, reach_of_snap, swept_triangles)
                            && may_snap(b);
        if (snap_a)
          put_on_surface(a);
        if (snap_b)
          put_on_surface(b);
        if (snap_a || snap_b)
          continue;
        crossings.emplace(key, crossing);
        ++crossings_at[a];
        ++crossings_at[b];
        new_crossings.push_back(key);
      }
    keep_part_sweep(swept_triangles);
  }


  Cutter::Crossing
  Cutter::edge_crossing(const unsigned int                         a,
                        const unsigned int                         b,
                        const std::array<std::array<Point, 3>, 2> &swept_triangles,
                        const Point                               &normal,
                        std::array<double, 2>                     &distance) const
  {
    const Point pa = position(a), pb = position(b);
    for (const auto &tri : swept_triangles)
    {
      // The ends' sides: as decided for this part of the surface (the tissue may have
      // carried an end across the blade's plane since), or where they are now,
      // exactly (a point on the plane counts as on the positive side).
      const auto side_now = [&](const unsigned int v, const Point &x)
      {
        const std::int8_t kept = kept_side(v, normal);
        return kept != 0
                 ? kept
                 : (orientation(tri[0], tri[1], tri[2], x) >= 0 ? std::int8_t(1)
                                                                : std::int8_t(-1));
      };
      const std::int8_t sa = side_now(a, pa), sb = side_now(b, pb);
      if (sa == sb || !line_meets_triangle(pa, pb, tri[0], tri[1], tri[2]))
        continue;
      // Where (the decision above is exact; the place only needs to be close): the
      // parameter from a, the end with the smaller id, the same at rest as deformed.
      const Point  n  = cross(sub(tri[1], tri[0]), sub(tri[2], tri[0]));
      const double da = dot(n, sub(pa, tri[0])), db = dot(n, sub(pb, tri[0]));
      const double t = da == db ? 0.5 : std::clamp(da / (da - db), 0.0, 1.0);
      // The ends' distances from the surface's plane, in edge lengths.
      const double scale = norm(n) * norm(sub(pb, pa));
      distance           = scale > 0
                             ? std::array<double, 2>{{std::abs(da) / scale, std::abs(db) / scale}}
                             : std::array<double, 2>{{1, 1}};
      return {t, sa, false};
    }
    return {};
  }


  std::int8_t
  Cutter::kept_side(const unsigned int v, const Point &normal) const
  {
    if (v >= side_records.size())
      return 0;
    const SideRecord &r = side_records[v];
    return r.stroke == stroke && dot(r.normal, normal) > same_part_cosine ? r.side : 0;
  }


  void
  Cutter::keep_side(const unsigned int v, const std::int8_t side, const Point &normal)
  {
    if (side_records.size() <= v)
      side_records.resize(std::size_t(v) + 256);
    if (kept_side(v, normal) == 0)
      side_records[v] = {side, stroke, normal};
  }


  double
  Cutter::cell_size_around(const unsigned int a, const unsigned int b) const
  {
    // A cell's size: its longest edge at rest. A layer that earlier cuts made thin
    // keeps the size of the cell it came from, so that the next cut beside it does not
    // thin it again (each cut would otherwise take a fraction of what the last left).
    double size = 0;
    mesh.visit_tets_with_edge(a,
                              b,
                              [&](const unsigned int t, unsigned int)
                              {
                                const mesh::Tet &tet = mesh.tet(t);
                                for (const auto &e : tet_edge_vertices)
                                  size = std::max(size,
                                                  norm(sub(mesh.vertex(tet[e[1]]),
                                                           mesh.vertex(tet[e[0]]))));
                                return false;
                              });
    return size;
  }


  bool
  Cutter::may_snap(const unsigned int v) const
  {
    // Not if a crossing of another of its edges was decided (it lies off the cut),
    // nor if a cell around it would have all four vertices on the cut: such a cell
    // lies in the crack and would be cut off from both sides, a fragment.
    if (crossings_at[v] != 0)
      return false;
    for (const unsigned int t : mesh.tets_of_vertex(v))
    {
      unsigned int others_on_cut = 0;
      for (const unsigned int w : mesh.tet(t))
        others_on_cut += w != v && on_surface[w];
      if (others_on_cut == 3)
        return false;
    }
    return true;
  }


  void
  Cutter::put_on_surface(const unsigned int v)
  {
    mark_on_surface(v);
    new_on_surface.push_back(v);
  }


  Cutter::CellDecision
  Cutter::decide_cell(const unsigned int t) const
  {
    const mesh::Tet           &tet = mesh.tet(t);
    CellDecision               d;
    std::array<bool, 4>        zero;
    std::array<std::int8_t, 6> side_of_smaller{};
    for (unsigned int i = 0; i < 4; ++i)
      zero[i] = on_surface[tet[i]] != 0;
    for (unsigned int e = 0; e < 6; ++e)
    {
      const unsigned int i = tet_edge_vertices[e][0], j = tet_edge_vertices[e][1];
      if (zero[i] || zero[j])
        continue;
      const auto it = crossings.find(edge_key(tet[i], tet[j]));
      if (it == crossings.end())
        continue;
      d.crossed |= std::uint8_t(1u << e);
      d.t[e]             = it->second.t;
      side_of_smaller[e] = it->second.side;
    }
    if (d.crossed == 0)
      return d;
    // The two sides: a crossed edge joins vertices on opposite sides, its end with
    // the smaller id on the side the crossing recorded; an edge not crossed joins
    // vertices on the same side. The cell is cut through when that is consistent:
    // then its sides are those of the surface's orientation, the same in every cell.
    unsigned int first_edge = 0;
    while (!((d.crossed >> first_edge) & 1u))
      ++first_edge;
    {
      const unsigned int i            = tet_edge_vertices[first_edge][0],
                         j            = tet_edge_vertices[first_edge][1];
      const std::int8_t s             = side_of_smaller[first_edge];
      d.side[tet[i] < tet[j] ? i : j] = s;
      d.side[tet[i] < tet[j] ? j : i] = std::int8_t(-s);
      for (unsigned int k = 0; k < 4; ++k)
        if (k != i && k != j && !zero[k])
          d.side[k] = (d.crossed >> tet_edge_of_vertices[i][k]) & 1u
                        ? std::int8_t(-d.side[i])
                        : d.side[i];
    }
    bool consistent = true;
    for (unsigned int e = 0; e < 6; ++e)
    {
      const unsigned int i = tet_edge_vertices[e][0], j = tet_edge_vertices[e][1];
      if (zero[i] || zero[j])
        continue;
      if ((d.crossed >> e) & 1u)
        consistent &=
          d.side[tet[i] < tet[j] ? i : j] == side_of_smaller[e] && d.side[i] != d.side[j];
      else
        consistent &= d.side[i] == d.side[j];
    }
    d.complete = consistent && d.crossed != 0;
    return d;
  }


  void
  Cutter::select_cells()
  {
    ++affected_stamp;
    affected.clear();
    applied_crossings.clear();
    const auto consider = [&](const unsigned int t)
    {
      if (tet_mark[t] != affected_stamp)
      {
        tet_mark[t] = affected_stamp;
        in_star[t]  = 0;
        affected.push_back(t);
      }
    };
    const auto consider_edge = [&](const std::uint64_t key)
    {
      around.clear();
      mesh.tets_around_edge(edge_end(key, 0), edge_end(key, 1), around);
      for (const unsigned int n : around)
        consider(n);
    };
    // The cells whose copies of @p v are decided again: its whole star.
    const auto separate = [&](const unsigned int v)
    {
      if (separate_mark[v] == affected_stamp)
        return;
      separate_mark[v] = affected_stamp;
      for (const unsigned int n : mesh.tets_of_vertex(v))
      {
        consider(n);
        in_star[n] = 1;
      }
    };
    for (const std::uint64_t key : new_crossings)
      consider_edge(key);
    new_on_surface.insert(new_on_surface.end(), adopted.begin(), adopted.end());
    adopted.clear();
    for (const unsigned int v : new_on_surface)
      fresh_mark[v] = affected_stamp;
    for (const unsigned int v : new_on_surface)
      separate(v);
    // The closure: a cell cut through applies its crossings, and every cell around
    // an applied crossing is split with it (conforming: it is refined through the
    // cut point if the surface does not cross it through yet); the vertices on the
    // cut in a cell cut through get their copies decided over their whole stars.
    for (std::size_t q = 0; q < affected.size(); ++q)
    {
      const unsigned int t   = affected[q];
      const mesh::Tet   &tet = mesh.tet(t);
      // A face whose last vertex came onto the cut in this sweep lies in the cut from
      // now on: the copies of all three of its vertices are decided again.
      for (const auto &fv : mesh::TetMesh::face_vertices)
        if (on_surface[tet[fv[0]]] && on_surface[tet[fv[1]]] && on_surface[tet[fv[2]]]
            && (fresh_mark[tet[fv[0]]] == affected_stamp
                || fresh_mark[tet[fv[1]]] == affected_stamp
                || fresh_mark[tet[fv[2]]] == affected_stamp))
          for (const unsigned int k : fv)
            separate(tet[k]);
      const CellDecision d = decide_cell(t);
      if (!d.complete)
        continue;
      for (unsigned int e = 0; e < 6; ++e)
        if ((d.crossed >> e) & 1u)
        {
          const std::uint64_t key =
            edge_key(tet[tet_edge_vertices[e][0]], tet[tet_edge_vertices[e][1]]);
          Crossing &c = crossings.find(key)->second;
          if (!c.applied)
          {
            c.applied = true;
            applied_crossings.push_back(key);
            consider_edge(key);
          }
        }
      for (const unsigned int v : tet)
        if (on_surface[v])
          separate(v);
    }
  }


  void
  Cutter::make_cuts()
  {
    removed.clear();
    cuts.clear();
    for (const unsigned int t : affected)
    {
      const CellDecision d   = decide_cell(t);
      const mesh::Tet   &tet = mesh.tet(t);
      TetCut             c   = whole_cell(t);
      if (d.complete)
        for (unsigned int i = 0; i < 4; ++i)
          c.vertex_side[i] = d.side[i];
      for (unsigned int e = 0; e < 6; ++e)
        if ((d.crossed >> e) & 1u)
        {
          const bool applied = d.complete
                               || crossings
                                    .find(edge_key(tet[tet_edge_vertices[e][0]],
                                                   tet[tet_edge_vertices[e][1]]))
                                    ->second.applied;
          if (applied)
          {
            c.cut_edges |= std::uint8_t(1u << e);
            c.edge_parameter[e] = d.t[e];
          }
        }
      // A cell that is neither cut nor refined nor in the star of a vertex whose
      // copies are decided stays as it is.
      if (c.cut_edges == 0 && !in_star[t])
        continue;
      removed.push_back(t);
      cuts.push_back(c);
    }
  }


  TetCut
  Cutter::whole_cell(const unsigned int t) const
  {
    // Its vertices off the cut on one side: the side they were found on, or for those
    // the stroke has not judged, their side of the sweep's plane (a face whose last
    // vertex came onto the cut in this sweep lies in that plane), if they agree, so
    // that the faces the table flags face the surface's orientation (the MT's update
    // orients the cut surface by it).
    const mesh::Tet &tet      = mesh.tet(t);
    std::int8_t      one_side = 0;
    bool             agree    = true;
    for (const unsigned int v : tet)
      if (!on_surface[v])
      {
        const std::int8_t side =
          v < side_records.size() && side_records[v].stroke == stroke
            ? side_records[v].side
            : (orientation(
                 sweep_triangle[0], sweep_triangle[1], sweep_triangle[2], position(v))
                   >= 0
                 ? std::int8_t(1)
                 : std::int8_t(-1));
        agree &= one_side == 0 || one_side == side;
        one_side = side;
      }
    if (one_side == 0 || !agree)
      one_side = 1;
    TetCut c;
    for (unsigned int i = 0; i < 4; ++i)
    {
      c.vertex_ids[i]  = tet[i];
      c.points[i]      = mesh.vertex(tet[i]);
      c.vertex_side[i] = on_surface[tet[i]] ? 0 : one_side;
    }
    return c;
  }


  void
  Cutter::forget_applied_crossings()
  {
    for (const std::uint64_t key : applied_crossings)
      forget_crossing(crossings.find(key));
    applied_crossings.clear();
  }


  std::unordered_map<std::uint64_t, Cutter::Crossing>::iterator
  Cutter::forget_crossing(const std::unordered_map<std::uint64_t, Crossing>::iterator it)
  {
    --crossings_at[edge_end(it->first, 0)];
    --crossings_at[edge_end(it->first, 1)];
    return crossings.erase(it);
  }


  unsigned int
  Cutter::new_particle(const Point       &rest,
                       const unsigned int parent,
                       CutStepStatistics &statistics)
  {
    // The state interpolated from the parent: the same affine map at rest and deformed.
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
  }


  void
  Cutter::make_children(CutStepStatistics &statistics, CutRecord *record)
  {
    // New points, merged across tetrahedra through the edge they lie on (one particle
    // per edge), interior points per cell; boundary ids inherited from the parent.
    ++merge_stamp;
    children.clear();
    child_cut_faces.clear();
    face_ids.clear();
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
                es.point       = mesh::invalid_index;
              }
              // One point per edge: its copies, where the crack opens, are decided
              // with the vertices on the cut (below).
              slot = &es.point;
              break;
            }
            case NodeKind::face_point:
              // The cutter's cuts have no crack front inside a cell.
              AssertThrow(false, dealii::ExcInternalError());
              DEAL_II_FALLTHROUGH;
            default:
              slot = &interior;
              break;
          }
          if (*slot == mesh::invalid_index)
          {
            const Point p =
              n.kind == NodeKind::edge_point ? r.edge_points[n.index] : r.interior_point;
            *slot = new_particle(p, parent, statistics);
            if (record)
            {
              record->new_points.push_back({*slot, n.kind, record_key(c, n), p});
            }
            if (n.kind != NodeKind::interior_point)
            {
              mark_on_surface(*slot);
              if (separate_mark.size() <= *slot)
                separate_mark.resize(std::size_t(*slot) + 256, 0);
              separate_mark[*slot] = affected_stamp;
            }
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
      }
    }
  }


  void
  Cutter::separate_points_on_cut(CutStepStatistics &statistics, CutRecord *record)
  {
    // Vertices on the cut: one copy per group of their children connected through
    // faces not on the cut, so that the two sides separate where the crack is open
    // and stay joined at the crack tip.
    incidences.clear();
    for (std::size_t k = 0; k < children.size(); ++k)
      for (const unsigned int v : children[k])
        if (v < separate_mark.size() && separate_mark[v] == affected_stamp)
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
            {copy, NodeKind::vertex, {{v, 0, 0, 0}}, mesh.vertex(v)});
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
  }


  void
  Cutter::index_new_boundary_faces()
  {
    prepare_scratch();
    for (const unsigned int t : added_ids)
      for (unsigned int f = 0; f < 4; ++f)
        if (mesh.neighbor(t, f) == mesh::invalid_index)
          tree.add_face(mesh, t, f);
    // A vertex that lost all its cells cannot happen (copies take over whole stars),
    // but a mass that rounding left a hair below zero would be nonsense: clamp. A mass
    // further below zero is a particle that gave mass to its neighbours
    // (physics::MassBalancer) and lost cells since: the balancer raises it again, and
    // clamping it would add mass.
    const double rounding = 1e-12 * std::abs(integral_of_density);
    for (const unsigned int v : topology.touched_particles())
      if (system.mass[v] < 0 && system.mass[v] > -rounding)
        system.mass[v] = 0;
  }


  void
  Cutter::update_active_cells(const Blade &end)
  {
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
  }


  void
  Cutter::apply(const Blade &end, CutStepStatistics &statistics)
  {
    // The terms of the cells that go, from the masses and from the springs of their
    // edges (by edge id, before the mesh update moves the ids; a spring whose edge
    // dies is retired with it). Every spring gets these terms first and those of the
    // new cells after, in the order of the cells.
    topology.clear_touched();
    const double mass_before = topology.mass_delta();
    topology.take_out(removed);
    lap(statistics.physics_seconds);

    // The record of this sweep for the Multi-Triangulation (set_recorder()).
    CutRecord *record = recorder ? &recorder->emplace_back() : nullptr;
    if (record)
    {
      record->cuts          = cuts;
      record->snap_fraction = parameters.snap_fraction;
      child_origin.clear();
    }
    make_children(statistics, record);
    separate_points_on_cut(statistics, record);
    lap(statistics.children_seconds);

    // The mesh, locally.
    added_ids = topology.replace(removed, children, face_ids);
    lap(statistics.mesh_seconds);

    index_new_boundary_faces();
    integral_of_density += topology.mass_delta() - mass_before;
    update_active_cells(end);
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
    // Their copies are decided again in the next sweep (the faces between them lie
    // in the cut): where the crack was closed, it opens.
    for (const unsigned int v : crack)
    {
      AssertIndexRange(v, mesh.n_vertices());
      mark_on_surface(v);
      adopted.push_back(v);
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
      on_surface[v] = 1;
      on_surface_list.push_back(v);
    }
  }


  void
  Cutter::serialize(Archive &archive)
  {
    // What a blade motion leaves for the next one; the rest is scratch of a motion.
    archive.section("cutter");
    archive(current, typical_edge, tree, active, on_surface, on_surface_list);
    archive(side_records, blade_cell_positions, stroke, crossings, crossings_at, adopted);
    archive(part.normal, part.triangles);
  }
} // namespace lacerta::cut
