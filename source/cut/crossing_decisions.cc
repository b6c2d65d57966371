#include <lacerta/base/archive.h>
#include <lacerta/cut/crossing_decisions.h>
#include <lacerta/cut/geometry.h>
#include <lacerta/cut/predicates.h>
#include <lacerta/mesh/tet_mesh.h>
#include <lacerta/physics/particle_system.h>

#include <deal.II/base/exceptions.h>

#include <algorithm>
#include <cmath>

namespace lacerta::cut
{
  namespace
  {
    /// Two sweeps are the same part of the swept surface, for the sides of the
    /// vertices next to it, when their normals are less than 45 degrees apart: the
    /// blade cutting on along a path that bends gradually. A sharper turn (a corner,
    /// a path that comes back across its own cut) is another part, on which the
    /// vertices' sides are decided anew.
    constexpr double same_part_cosine = 0.7071067811865476;
  } // namespace


  CrossingDecisions::CrossingDecisions(const mesh::TetMesh           &mesh_in,
                                       const physics::ParticleSystem &system_in,
                                       const double                   snap_fraction_in)
      : mesh(mesh_in)
      , system(system_in)
      , snap_fraction(snap_fraction_in)
  {
    on_surface.assign(mesh.n_vertices(), 0);
    prepare();
  }


  void
  CrossingDecisions::reserve(const std::size_t n_vertices, const std::size_t n_edges)
  {
    edge_seen.reserve(n_edges);
    on_surface.reserve(n_vertices);
    crossings_at.reserve(n_vertices);
  }


  void
  CrossingDecisions::prepare()
  {
    edge_seen.resize(mesh.n_edges(), 0);
    if (on_surface.size() < mesh.n_vertices())
      on_surface.resize(mesh.n_vertices(), 0);
    crossings_at.resize(mesh.n_vertices(), 0);
  }


  Point
  CrossingDecisions::position(const unsigned int v) const
  {
    return system.current_position(v);
  }


  void
  CrossingDecisions::end_stroke()
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
  CrossingDecisions::follow_part(const Point &normal)
  {
    // A zero normal (a new stroke) is never the same part.
    if (dot(part.normal, normal) <= same_part_cosine)
      part.triangles.clear();
    part.normal = normal;
  }


  void
  CrossingDecisions::keep_part_sweep(const SweptTriangles &swept_triangles)
  {
    if (part.triangles.size() >= 2 * std::size_t(kept_part_sweeps))
      part.triangles.erase(part.triangles.begin(), part.triangles.begin() + 2);
    part.triangles.insert(part.triangles.end(),
                          swept_triangles.begin(),
                          swept_triangles.end());
  }


  bool
  CrossingDecisions::part_reaches(const unsigned int    v,
                                  const double          distance,
                                  const SweptTriangles &swept_triangles) const
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


  void
  CrossingDecisions::record_sweep(const std::vector<unsigned int> &cells,
                                  const SweptTriangles            &swept_triangles)
  {
    const double eps = snap_fraction;
    fresh_crossings.clear();
    fresh_on_cut.clear();
    // The vertices of an adopted crack are this sweep's too.
    const auto take_adopted = [this]()
    {
      fresh_on_cut.insert(fresh_on_cut.end(), adopted.begin(), adopted.end());
      adopted.clear();
    };
    // The orientation of this part of the swept surface.
    Point normal = cross(sub(swept_triangles[0][1], swept_triangles[0][0]),
                         sub(swept_triangles[0][2], swept_triangles[0][0]));
    if (!(norm(normal) > 0))
      normal = cross(sub(swept_triangles[1][1], swept_triangles[1][0]),
                     sub(swept_triangles[1][2], swept_triangles[1][0]));
    if (!(norm(normal) > 0))
    {
      take_adopted();
      return; // the blade moved along itself: it sweeps no surface
    }
    normal         = normalized(normal);
    sweep_triangle = swept_triangles[0];
    follow_part(normal);
    ++sweep_stamp;
    for (const unsigned int t : cells)
      for (unsigned int e = 0; e < 6; ++e)
      {
        unsigned int &seen = edge_seen[mesh.tet_edges(t)[e]];
        if (seen == sweep_stamp)
          continue;
        seen           = sweep_stamp;
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
            fresh_crossings.push_back(key);
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
          put_on_cut(a);
        if (snap_b)
          put_on_cut(b);
        if (snap_a || snap_b)
          continue;
        crossings.emplace(key, crossing);
        ++crossings_at[a];
        ++crossings_at[b];
        fresh_crossings.push_back(key);
      }
    keep_part_sweep(swept_triangles);
    take_adopted();
  }


  CrossingDecisions::Crossing
  CrossingDecisions::edge_crossing(const unsigned int     a,
                                   const unsigned int     b,
                                   const SweptTriangles  &swept_triangles,
                                   const Point           &normal,
                                   std::array<double, 2> &distance) const
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
  CrossingDecisions::kept_side(const unsigned int v, const Point &normal) const
  {
    if (v >= side_records.size())
      return 0;
    const SideRecord &r = side_records[v];
    return r.stroke == stroke && dot(r.normal, normal) > same_part_cosine ? r.side : 0;
  }


  void
  CrossingDecisions::keep_side(const unsigned int v,
                               const std::int8_t  side,
                               const Point       &normal)
  {
    if (side_records.size() <= v)
      side_records.resize(std::size_t(v) + 256);
    if (kept_side(v, normal) == 0)
      side_records[v] = {side, stroke, normal};
  }


  double
  CrossingDecisions::cell_size_around(const unsigned int a, const unsigned int b) const
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
  CrossingDecisions::may_snap(const unsigned int v) const
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
  CrossingDecisions::put_on_cut(const unsigned int v)
  {
    mark_on_cut(v);
    fresh_on_cut.push_back(v);
  }


  CrossingDecisions::CellDecision
  CrossingDecisions::decide_cell(const unsigned int t) const
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


  TetCut
  CrossingDecisions::whole_cell(const unsigned int t) const
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


  bool
  CrossingDecisions::apply_crossing(const std::uint64_t key)
  {
    Crossing &c = crossings.find(key)->second;
    if (c.applied)
      return false;
    c.applied = true;
    applied_crossings.push_back(key);
    return true;
  }


  bool
  CrossingDecisions::is_applied(const std::uint64_t key) const
  {
    return crossings.find(key)->second.applied;
  }


  void
  CrossingDecisions::forget_applied()
  {
    for (const std::uint64_t key : applied_crossings)
      forget_crossing(crossings.find(key));
    applied_crossings.clear();
  }


  std::unordered_map<std::uint64_t, CrossingDecisions::Crossing>::iterator
  CrossingDecisions::forget_crossing(
    const std::unordered_map<std::uint64_t, Crossing>::iterator it)
  {
    --crossings_at[edge_end(it->first, 0)];
    --crossings_at[edge_end(it->first, 1)];
    return crossings.erase(it);
  }


  void
  CrossingDecisions::mark_on_cut(const unsigned int v)
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
  CrossingDecisions::adopt(const std::vector<unsigned int> &crack)
  {
    for (const unsigned int v : crack)
    {
      AssertIndexRange(v, mesh.n_vertices());
      mark_on_cut(v);
      adopted.push_back(v);
    }
  }


  void
  CrossingDecisions::serialize(Archive &archive)
  {
    archive.section("crossing decisions");
    archive(on_surface, on_surface_list, side_records, stroke, crossings, crossings_at);
    archive(adopted, part.normal, part.triangles);
  }
} // namespace lacerta::cut
