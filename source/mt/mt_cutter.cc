#include <lacerta/base/exceptions.h>
#include <lacerta/cut/cutter.h>
#include <lacerta/mt/mt_cutter.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <map>
#include <set>
#include <tuple>

namespace lacerta::mt
{
  namespace
  {
    using cut::NodeKind;
    using cut::Point;

    /// Identity of a point a sweep creates, in MT vertex ids (sorted).
    struct Key
    {
      NodeKind                     kind;
      std::int8_t                  side;
      std::array<std::uint32_t, 4> ids;

      bool
      operator<(const Key &o) const
      {
        return std::tie(kind, side, ids) < std::tie(o.kind, o.side, o.ids);
      }
    };

    template <std::size_t n>
    std::array<std::uint32_t, 4>
    sorted_ids(std::array<std::uint32_t, n> ids)
    {
      std::sort(ids.begin(), ids.end());
      std::array<std::uint32_t, 4> result{};
      std::copy(ids.begin(), ids.end(), result.begin());
      return result;
    }

    std::pair<std::uint32_t, std::uint32_t>
    edge_key(const std::uint32_t a, const std::uint32_t b)
    {
      return {std::min(a, b), std::max(a, b)};
    }

    /// The position of a node of a child of @p c split into @p r.
    Point
    node_position(const cut::TetCut &c, const cut::SplitResult &r, const cut::NodeRef &n)
    {
      switch (n.kind)
      {
        case NodeKind::vertex:
          return c.points[n.index];
        case NodeKind::edge_point:
          return r.edge_points[n.index];
        case NodeKind::face_point:
          return r.face_points[n.index];
        case NodeKind::interior_point:
          break;
      }
      return r.interior_point;
    }
  } // namespace


  MtCutter::MtCutter(MultiTriangulation &mt_in,
                     const double        snap_fraction_in,
                     const double        boundary_error)
      : mt(mt_in)
      , snap_fraction(snap_fraction_in)
  {
    cut::Box all;
    for (const auto &p : mt.vertices)
      all.extend(p);
    rim_extension = 2 * boundary_error * cut::norm(cut::sub(all.upper, all.lower));
    // About eight tetrahedra per cell: a query near the cut touches few cells.
    const double target = std::max(1.0, mt.n_tets() / 8.0);
    double       volume = 1;
    for (unsigned int d = 0; d < 3; ++d)
      volume *= std::max(all.upper[d] - all.lower[d], 1e-12);
    cell   = std::cbrt(volume / target);
    origin = all.lower;
    for (unsigned int d = 0; d < 3; ++d)
      dims[d] = std::max(1u,
                         std::min(1024u,
                                  static_cast<unsigned int>(
                                    std::ceil((all.upper[d] - all.lower[d]) / cell))));
    cells.resize(std::size_t(dims[0]) * dims[1] * dims[2]);
    vertex_tets.resize(mt.n_vertices());
    for (std::uint32_t t = 0; t < mt.n_tets(); ++t)
      if (mt.is_live(t))
        index_tet(t);
  }


  cut::Box
  MtCutter::tet_box(const std::uint32_t t) const
  {
    cut::Box box;
    for (const auto v : mt.tets[t])
      box.extend(mt.vertices[v]);
    return box;
  }


  void
  MtCutter::index_tet(const std::uint32_t t)
  {
    for_each_cell(tet_box(t), [&](const std::size_t k) { cells[k].push_back(t); });
    if (vertex_tets.size() < mt.n_vertices())
      vertex_tets.resize(mt.n_vertices());
    for (const auto v : mt.tets[t])
      vertex_tets.insert(v, t);
  }


  void
  MtCutter::query(const cut::Box &box, std::vector<std::uint32_t> &out)
  {
    seen.resize(mt.n_tets(), 0);
    if (++stamp == 0)
    {
      std::fill(seen.begin(), seen.end(), 0);
      stamp = 1;
    }
    for_each_cell(box,
                  [&](const std::size_t k)
                  {
                    for (const std::uint32_t t : cells[k])
                      if (seen[t] != stamp)
                      {
                        seen[t] = stamp;
                        if (mt.is_live(t) && tet_box(t).overlaps(box))
                          out.push_back(t);
                      }
                  });
  }


  void
  MtCutter::replace_in_fragments(const std::uint32_t               parent,
                                 const std::vector<std::uint32_t> &children)
  {
    const auto replace = [&](std::vector<std::uint32_t> &list)
    {
      auto it = std::find(list.begin(), list.end(), parent);
      if (it == list.end())
        throw_error("MtCutter: internal error, tet ", parent, " not in its fragment.");
      *it = children.front();
      list.insert(list.end(), children.begin() + 1, children.end());
    };
    const std::uint32_t c = mt.creator[parent];
    if (mt.cut_fine[c].empty())
      for (std::uint32_t t = mt.fine_begin[c]; t < mt.fine_begin[c + 1]; ++t)
        mt.cut_fine[c].push_back(t);
    replace(mt.cut_fine[c]);
    const std::uint32_t d = mt.destroyer[parent];
    if (d == mesh::invalid_index)
      return;
    if (mt.cut_coarse[d].empty())
      for (std::uint32_t k = mt.coarse_begin[d]; k < mt.coarse_begin[d + 1]; ++k)
        mt.cut_coarse[d].push_back(mt.coarse_list[k]);
    replace(mt.cut_coarse[d]);
  }


  MtCutter::Statistics
  MtCutter::apply(const std::vector<cut::CutRecord> &records,
                  Lod                               *lod,
                  const mesh::TetMesh               *cut_mesh)
  {
    const auto start = std::chrono::steady_clock::now();
    Statistics statistics;
    if (mt.replaced.empty())
      mt.replaced.assign(mt.n_tets(), 0);
    if (mt.cut_fine.empty())
    {
      mt.cut_fine.resize(mt.n_nodes());
      mt.cut_coarse.resize(mt.n_nodes());
    }
    const double eps = snap_fraction;

    // 1. The rest cut surface: the cut faces of the +1 children of every recorded
    // split, normals towards +1, in a grid like the tets'.
    std::vector<std::array<Point, 3>>       surface;
    std::vector<Point>                      normal;
    std::vector<std::vector<std::uint32_t>> surface_cells(cells.size());
    std::vector<cut::Box>                   regions;
    const auto add_triangle = [&](const std::array<Point, 3> &tri, const Point &n)
    {
      for_each_cell(cut::Box::around(tri),
                    [&](const std::size_t k) {
                      surface_cells[k].push_back(
                        static_cast<std::uint32_t>(surface.size()));
                    });
      surface.push_back(tri);
      normal.push_back(n);
    };
    // The edges of the cut mesh's boundary faces that are not on the cut (its outer
    // boundary), by the rest positions of their ends; edges of cut faces among them
    // are the surface's rim.
    const auto undirected = [](const Point &a, const Point &b)
    { return a < b ? std::make_pair(a, b) : std::make_pair(b, a); };
    // Only faces that meet the box of the records' cut tetrahedra can share an edge
    // with the surface: the set grows with the cut, not with the boundary.
    std::set<std::pair<Point, Point>> outer_edges;
    if (cut_mesh && rim_extension > 0)
    {
      cut::Box cut_box;
      for (const auto &record : records)
        for (const auto &c : record.cuts)
          for (const auto &p : c.points)
            cut_box.extend(p);
      for (const auto &f : cut_mesh->get_boundary_faces())
        if (f.boundary_id != cut::cut_boundary_id)
        {
          const auto &l = mesh::TetMesh::face_vertices[f.face];
          const auto &t = cut_mesh->tet(f.tet);
          cut::Box    face_box;
          for (const unsigned int k : l)
            face_box.extend(cut_mesh->vertex(t[k]));
          if (!face_box.overlaps(cut_box))
            continue;
          for (unsigned int k = 0; k < 3; ++k)
            outer_edges.insert(
              undirected(cut_mesh->vertex(t[l[k]]), cut_mesh->vertex(t[l[(k + 1) % 3]])));
        }
    }
    struct RimEdge
    {
      Point a, b, inner, normal;
    };
    std::vector<RimEdge> rim;
    for (const auto &record : records)
    {
      cut::Box region;
      for (const auto &c : record.cuts)
      {
        for (const auto &p : c.points)
          region.extend(p);
        cut::SplitResult r;
        cut::split_tetrahedron(c, r, eps);
        for (unsigned int i = 0; i < r.n_children; ++i)
        {
          const cut::Child &child = r.children[i];
          if (child.side == 0)
            continue;
          for (unsigned int j = 0; j < 4; ++j)
            if ((child.cut_faces >> j) & 1u)
            {
              std::array<Point, 3> tri;
              for (unsigned int k = 0; k < 3; ++k)
                tri[k] = node_position(c, r, child.nodes[(j + 1 + k) % 4]);
              Point n = cut::cross(cut::sub(tri[1], tri[0]), cut::sub(tri[2], tri[0]));
              if (cut::dot(n, cut::sub(node_position(c, r, child.nodes[j]), tri[0]))
                    * child.side
                  < 0)
                n = cut::scale(-1, n);
              add_triangle(tri, n);
              if (child.side > 0 && !outer_edges.empty())
                for (unsigned int k = 0; k < 3; ++k)
                  if (outer_edges.count(undirected(tri[k], tri[(k + 1) % 3])))
                    rim.push_back({tri[k], tri[(k + 1) % 3], tri[(k + 2) % 3], n});
            }
        }
      }
      if (!record.cuts.empty())
        regions.push_back(region);
    }
    // The surface ends on the boundary of the level of detail that was cut; the other
    // levels' boundaries lie up to twice the decimation's Hausdorff bound outside it
    // (each within the bound of the input's), and a tetrahedron sticking out there
    // would meet the surface's rim inside it: the crack would close there and keep a
    // bridge along the rim (seen on the kidney, at levels coarse near the cut). Each
    // rim edge is therefore extended outwards, in its cut face's plane, by
    // rim_extension. Crack fronts and bridges the cutter left inside are not extended.
    for (const RimEdge &e : rim)
    {
      const Point &a = e.a, &b = e.b, &c = e.inner, &n = e.normal;
      Point        u      = cut::cross(n, cut::sub(b, a));
      const double length = cut::norm(u);
      if (!(length > 0))
        continue;
      u = cut::scale(rim_extension / length, u);
      if (cut::dot(u, cut::sub(c, a)) > 0)
        u = cut::scale(-1, u);
      const Point    a_out = cut::add(a, u), b_out = cut::add(b, u);
      const cut::Box flap = cut::Box::around(std::array<Point, 4>{{a, b, a_out, b_out}});
      for (const std::array<Point, 3> &tri :
           {std::array<Point, 3>{{a, b, b_out}}, std::array<Point, 3>{{a, b_out, a_out}}})
        add_triangle(tri, n);
      regions.push_back(flap);
    }
    if (surface.empty())
      return statistics;
    // An earlier surface that ended inside tetrahedra (a partial tear or stroke; the
    // crack closed there, step 4) is cut again with these records if they reach those
    // tetrahedra: a continuation's records start at the old crack front, inside them,
    // and alone they would end there too and close the crack again (at a coarse level
    // whose cells all contain the old front, the continued tear never separated).
    // Only a surface that meets the kept one continues it: a stroke elsewhere, even
    // through the same coarse cells, leaves it alone (cutting it again there would
    // open faces whose corners all lie on it beyond where it ends).
    std::vector<cut::Box> kept_boxes;
    for (const auto &tri : kept_surface)
      kept_boxes.push_back(cut::Box::around(tri));
    bool reaches_kept = false;
    for (std::size_t k = 0; k < surface.size() && !reaches_kept; ++k)
    {
      const cut::Box box = cut::Box::around(surface[k]);
      reaches_kept =
        std::any_of(kept_boxes.begin(),
                    kept_boxes.end(),
                    [&](const cut::Box &kept) { return box.overlaps(kept); });
    }
    if (reaches_kept)
      for (std::size_t k = 0; k < kept_surface.size(); ++k)
      {
        add_triangle(kept_surface[k], kept_normal[k]);
        regions.push_back(kept_boxes[k]);
      }
    // The surface triangles near a box (each at most once per call).
    std::vector<std::uint32_t> triangle_seen(surface.size(), 0);
    std::uint32_t              triangle_stamp = 0;
    const auto near_triangles = [&](const cut::Box &box, std::vector<std::uint32_t> &out)
    {
      out.clear();
      ++triangle_stamp;
      for_each_cell(box,
                    [&](const std::size_t k)
                    {
                      for (const std::uint32_t t : surface_cells[k])
                        if (triangle_seen[t] != triangle_stamp)
                        {
                          triangle_seen[t] = triangle_stamp;
                          out.push_back(t);
                        }
                    });
    };

    // 2. The MT tetrahedra near the surface; the crossings of their edges, once per
    // edge, snapped by the cutter's rule.
    std::vector<std::uint32_t> candidates;
    for (const auto &region : regions)
      query(region, candidates);
    std::sort(candidates.begin(), candidates.end());
    candidates.erase(std::unique(candidates.begin(), candidates.end()), candidates.end());
    std::set<std::uint32_t> in_candidates(candidates.begin(), candidates.end());
    std::map<std::pair<std::uint32_t, std::uint32_t>, double> edge_t; // -1: not cut
    std::set<std::uint32_t>                                   on_cut;
    std::map<std::uint32_t, std::int8_t>                      hint;
    std::vector<std::uint32_t>                                near;
    const auto evaluate_edge = [&](const std::uint32_t a, const std::uint32_t b)
    {
      const auto key = edge_key(a, b);
      if (edge_t.count(key))
        return;
      double      result = -1;
      const Point p = mt.vertices[key.first], q = mt.vertices[key.second];
      cut::Box    box;
      box.extend(p);
      box.extend(q);
      near_triangles(box, near);
      for (const std::uint32_t k : near)
      {
        double s;
        if (!cut::segment_hits_triangle(
              p, q, surface[k][0], surface[k][1], surface[k][2], s, 1e-10))
          continue;
        // A crossing at a vertex puts the vertex on the cut: the edge is not cut.
        s                        = std::clamp(s, 0.0, 1.0);
        const cut::EdgeSnap snap = cut::snap_edge_parameter(s, eps);
        if (snap == cut::EdgeSnap::first_vertex)
          on_cut.insert(key.first);
        else if (snap == cut::EdgeSnap::second_vertex)
          on_cut.insert(key.second);
        else
        {
          result = s;
          const std::int8_t side_p =
            cut::dot(normal[k], cut::sub(p, surface[k][0])) >= 0 ? 1 : -1;
          hint.emplace(key.first, side_p);
          hint.emplace(key.second, -side_p);
        }
        break;
      }
      edge_t[key] = result;
    };
    // A vertex the cutter put on the cut is a corner of the surface, exactly.
    {
      std::set<Point> corners;
      for (const auto &tri : surface)
        corners.insert(tri.begin(), tri.end());
      for (const std::uint32_t t : candidates)
        for (const std::uint32_t v : mt.tets[t])
          if (corners.count(mt.vertices[v]))
            on_cut.insert(v);
    }
    // The whole star of a vertex on the cut is split (each side takes its copy).
    std::set<std::uint32_t> star_added;
    for (std::size_t q = 0; q < candidates.size(); ++q)
    {
      const auto tet = mt.tets[candidates[q]];
      for (const auto &e : cut::tet_edge_vertices)
        evaluate_edge(tet[e[0]], tet[e[1]]);
      if (q + 1 == candidates.size())
        for (const std::uint32_t v : on_cut)
          if (star_added.insert(v).second)
            for (const std::uint32_t t : vertex_tets[v])
              if (mt.is_live(t) && in_candidates.insert(t).second)
                candidates.push_back(t);
    }
    // Sides: from a crossing edge, else the plane of the nearest surface triangle.
    std::map<std::uint32_t, std::int8_t> side;
    const auto off_cut_side = [&](const std::uint32_t v) -> std::int8_t
    {
      const auto ih = hint.find(v);
      if (ih != hint.end())
        return ih->second;
      cut::Box box;
      box.extend(mt.vertices[v]);
      near_triangles(box, near);
      if (near.empty())
        for (std::uint32_t k = 0; k < surface.size(); ++k)
          near.push_back(k);
      double      best = 1e300;
      std::int8_t s    = 1;
      for (const std::uint32_t k : near)
      {
        const Point centre =
          cut::scale(1.0 / 3,
                     cut::add(surface[k][0], cut::add(surface[k][1], surface[k][2])));
        const Point  d  = cut::sub(mt.vertices[v], centre);
        const double d2 = cut::dot(d, d);
        if (d2 < best)
        {
          best = d2;
          s = cut::dot(normal[k], cut::sub(mt.vertices[v], surface[k][0])) >= 0 ? 1 : -1;
        }
      }
      return s;
    };
    const auto side_of = [&](const std::uint32_t v)
    {
      auto it = side.find(v);
      if (it == side.end())
        it = side.emplace(v, on_cut.count(v) ? 0 : off_cut_side(v)).first;
      return it->second;
    };

    // 3. The split of every candidate, from per-edge and per-vertex data only, so
    // that neighbours at every level of detail agree.
    struct Split
    {
      std::uint32_t    tet;
      cut::TetCut      cut;
      cut::SplitResult result;
    };
    std::vector<Split> splits;
    const auto         make_cut = [&](const std::uint32_t t, Split &s)
    {
      const auto &ids = mt.tets[t];
      s.tet           = t;
      s.cut           = cut::TetCut();
      bool touched    = false;
      for (unsigned int i = 0; i < 4; ++i)
      {
        s.cut.vertex_ids[i]  = ids[i];
        s.cut.points[i]      = mt.vertices[ids[i]];
        s.cut.vertex_side[i] = side_of(ids[i]);
        touched |= s.cut.vertex_side[i] == 0;
      }
      for (unsigned int e = 0; e < 6; ++e)
      {
        const unsigned int i = cut::tet_edge_vertices[e][0],
                           j = cut::tet_edge_vertices[e][1];
        const double p       = edge_t.at(edge_key(ids[i], ids[j]));
        if (p >= 0 && s.cut.vertex_side[i] * s.cut.vertex_side[j] < 0)
        {
          s.cut.cut_edges |= std::uint8_t(1u << e);
          s.cut.edge_parameter[e] = p;
          touched                 = true;
        }
      }
      return touched;
    };
    // Where the surface ends inside a tetrahedron (a crack front, or a bridge the
    // cutter left), the table refines it without separating: the points on its cut
    // edges are not separated in any tetrahedron, so the crack closes there.
    std::set<std::pair<std::uint32_t, std::uint32_t>> closed;
    std::vector<cut::Box>                             closed_tets;
    for (const std::uint32_t t : candidates)
    {
      Split s;
      if (!make_cut(t, s))
        continue;
      const cut::CutKind kind = cut::split_tetrahedron(s.cut, s.result, eps);
      if (kind == cut::CutKind::none)
        continue;
      if (kind != cut::CutKind::complete && kind != cut::CutKind::touch)
      {
        closed_tets.push_back(tet_box(t));
        for (unsigned int e = 0; e < 6; ++e)
          if ((s.cut.cut_edges >> e) & 1u)
            closed.insert(edge_key(s.cut.vertex_ids[cut::tet_edge_vertices[e][0]],
                                   s.cut.vertex_ids[cut::tet_edge_vertices[e][1]]));
      }
      splits.push_back(s);
    }

    // The surface near the tetrahedra in which it ended is kept for a continuation
    // (what was kept before is part of this surface if it was cut again).
    if (reaches_kept)
    {
      kept_surface.clear();
      kept_normal.clear();
    }
    if (!closed_tets.empty())
    {
      // The triangles in the grid cells those tetrahedra's boxes meet, each once.
      ++triangle_stamp;
      for (const cut::Box &box : closed_tets)
        for_each_cell(box,
                      [&](const std::size_t k)
                      {
                        for (const std::uint32_t t : surface_cells[k])
                          if (triangle_seen[t] != triangle_stamp)
                          {
                            triangle_seen[t] = triangle_stamp;
                            kept_surface.push_back(surface[t]);
                            kept_normal.push_back(normal[t]);
                          }
                      });
    }

    // 4. The children, with the cut points merged by edge and side, and the vertices
    // on the cut copied per group of children around them connected through faces
    // not on the cut (as the cutter does, over every level of detail at once).
    std::map<Key, std::uint32_t> point_of;
    const auto new_vertex = [&](const Point &x, const std::uint32_t origin_tet)
    {
      const auto id = static_cast<std::uint32_t>(mt.vertices.size());
      mt.vertices.push_back(x);
      mt.vertex_node.push_back(mt.creator[origin_tet]);
      mt.cut_origin.push_back(origin_tet);
      vertex_tets.resize(mt.vertices.size());
      ++statistics.new_vertices;
      return id;
    };
    std::vector<mesh::Tet>                            children;
    std::vector<std::uint8_t>                         child_cut_faces;
    std::vector<std::size_t>                          child_split;
    std::map<std::uint32_t, std::vector<std::size_t>> incident;
    for (std::size_t k = 0; k < splits.size(); ++k)
    {
      const Split &s = splits[k];
      for (unsigned int i = 0; i < s.result.n_children; ++i)
      {
        const cut::Child &child = s.result.children[i];
        mesh::Tet         tet;
        for (unsigned int j = 0; j < 4; ++j)
        {
          const cut::NodeRef &n = child.nodes[j];
          const auto         &v = s.cut.vertex_ids;
          if (n.kind == NodeKind::vertex)
          {
            tet[j] = static_cast<std::uint32_t>(v[n.index]);
            if (s.cut.vertex_side[n.index] == 0)
              incident[tet[j]].push_back(children.size());
            continue;
          }
          // Without fronts every new point is a point on an edge, separated unless
          // the crack closes there.
          const auto &e    = cut::tet_edge_vertices[n.index];
          const auto  edge = edge_key(static_cast<std::uint32_t>(v[e[0]]),
                                     static_cast<std::uint32_t>(v[e[1]]));
          const Key   key  = {n.kind,
                           closed.count(edge) ? std::int8_t(0) : n.side,
                              {{edge.first, edge.second, 0, 0}}};
          auto        it   = point_of.find(key);
          if (it == point_of.end())
            it =
              point_of.emplace(key, new_vertex(node_position(s.cut, s.result, n), s.tet))
                .first;
          tet[j] = it->second;
        }
        children.push_back(tet);
        child_cut_faces.push_back(child.cut_faces);
        child_split.push_back(k);
      }
    }
    // The tetrahedra around a vertex on the cut that the table leaves whole (the
    // surface does not cross them, though their vertices lie on both sides: it ends
    // nearby) keep the vertex and connect the children around them: left out, two
    // groups joined only through them got different vertices, and the faces between
    // them opened off the surface (a flap at the old tip of a continued tear).
    // The split tetrahedra are marked in `seen` with a stamp of their own.
    seen.resize(mt.n_tets(), 0);
    if (++stamp == 0)
    {
      std::fill(seen.begin(), seen.end(), 0);
      stamp = 1;
    }
    for (const Split &s : splits)
      seen[s.tet] = stamp;
    for (const auto &[v, list] : incident)
    {
      std::vector<mesh::Tet>    members;
      std::vector<std::uint8_t> member_cut_faces;
      for (const std::size_t c : list)
      {
        members.push_back(children[c]);
        member_cut_faces.push_back(child_cut_faces[c]);
      }
      for (const std::uint32_t t : vertex_tets[v])
        if (seen[t] != stamp && mt.is_live(t))
        {
          members.push_back(mt.tets[t]);
          member_cut_faces.push_back(0);
        }
      std::vector<std::size_t> group(members.size());
      for (std::size_t i = 0; i < members.size(); ++i)
        group[i] = i;
      const auto find = [&](std::size_t i)
      {
        while (group[i] != i)
          i = group[i] = group[group[i]];
        return i;
      };
      std::map<std::array<std::uint32_t, 3>, std::size_t> first_with_face;
      for (std::size_t i = 0; i < members.size(); ++i)
      {
        const mesh::Tet &t = members[i];
        for (unsigned int f = 0; f < 4; ++f)
        {
          if (t[f] == v || ((member_cut_faces[i] >> f) & 1u))
            continue;
          std::array<std::uint32_t, 3> face{
            {t[(f + 1) % 4], t[(f + 2) % 4], t[(f + 3) % 4]}};
          std::sort(face.begin(), face.end());
          const auto [it, inserted] = first_with_face.emplace(face, i);
          if (!inserted)
            group[find(i)] = find(it->second);
        }
      }
      // The groups of the whole tetrahedra keep the vertex, every other group gets a
      // copy.
      std::map<std::size_t, std::uint32_t> copy_of_root;
      for (std::size_t i = list.size(); i < members.size(); ++i)
        copy_of_root.emplace(find(i), v);
      for (std::size_t i = 0; i < list.size(); ++i)
      {
        const std::size_t root = find(i);
        auto              it   = copy_of_root.find(root);
        if (it == copy_of_root.end())
          it =
            copy_of_root
              .emplace(root,
                       copy_of_root.empty()
                         ? v
                         : new_vertex(mt.vertices[v], splits[child_split[list[i]]].tet))
              .first;
        for (auto &node : children[list[i]])
          if (node == v)
            node = it->second;
      }
    }

    // 5. The MT: children appended with their parent's creator and destroyer.
    std::vector<std::uint32_t> fragments;
    for (std::size_t c = 0, k = 0; k < splits.size(); ++k)
    {
      const Split               &s = splits[k];
      std::vector<std::uint32_t> ids;
      for (; c < children.size() && child_split[c] == k; ++c)
      {
        const auto id = static_cast<std::uint32_t>(mt.tets.size());
        mt.tets.push_back(children[c]);
        mt.creator.push_back(mt.creator[s.tet]);
        mt.destroyer.push_back(mt.destroyer[s.tet]);
        mt.replaced.push_back(0);
        ids.push_back(id);
      }
      mt.replaced[s.tet] = 1;
      replace_in_fragments(s.tet, ids);
      if (lod)
        lod->follow_cut(s.tet, ids);
      for (const std::uint32_t id : ids)
        index_tet(id);
      fragments.push_back(mt.creator[s.tet]);
      ++statistics.cut_tets;
      statistics.created_tets += static_cast<unsigned int>(ids.size());
    }
    std::sort(fragments.begin(), fragments.end());
    statistics.split_fragments = static_cast<unsigned int>(
      std::unique(fragments.begin(), fragments.end()) - fragments.begin());
    statistics.seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return statistics;
  }
} // namespace lacerta::mt
