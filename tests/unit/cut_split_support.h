/**
 * @file
 * Test support for the split table: tetrahedron shapes, a minimal mesh cutter on raw
 * arrays (global snapping, front points per face, point keys, vertex copies by
 * connected components), and geometric checks of splits and meshes. It mirrors what
 * the real cutter has to do, so that the tests exercise the table the way it will be
 * used.
 */
#pragma once

#include <lacerta/cut/cut_rules.h>
#include <lacerta/cut/cutter.h>
#include <lacerta/cut/geometry.h>
#include <lacerta/cut/split_table.h>
#include <lacerta/mesh/tet_mesh.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <map>
#include <numeric>
#include <random>
#include <set>
#include <sstream>
#include <string>
#include <vector>

namespace lacerta::cut::test_support
{
  // Vector algebra (sub, add, scale, lerp, dot, cross, norm, normalized, volume) comes
  // from the library's lacerta/cut/geometry.h, which the cutter uses too.

  inline double
  triangle_area(const Point &a, const Point &b, const Point &c)
  {
    return 0.5 * norm(cross(sub(b, a), sub(c, a)));
  }

  /**
   * Area of a planar convex polygon given by its corners in any order.
   */
  inline double
  convex_polygon_area(std::vector<Point> corners, const Point &normal)
  {
    if (corners.size() < 3)
      return 0;
    Point c{0, 0, 0};
    for (const auto &p : corners)
      c = add(c, scale(1.0 / corners.size(), p));
    const Point u = sub(corners[0], c);
    const Point w = cross(normal, u);
    std::sort(corners.begin(),
              corners.end(),
              [&](const Point &a, const Point &b)
              {
                return std::atan2(dot(w, sub(a, c)), dot(u, sub(a, c)))
                       < std::atan2(dot(w, sub(b, c)), dot(u, sub(b, c)));
              });
    double area = 0;
    for (std::size_t k = 1; k + 1 < corners.size(); ++k)
      area += triangle_area(corners[0], corners[k], corners[k + 1]);
    return area;
  }

  /**
   * Tetrahedron shapes, positively oriented: well-shaped random ones and the four
   * classical degenerate kinds.
   */
  enum class Shape
  {
    random,
    needle, // three vertices close together, the fourth far: one long thin spike
    sliver, // four vertices near a square, almost coplanar, no short edge
    cap,    // one vertex just above the centre of the opposite face
    wedge   // one short edge, the other two vertices far apart
  };

  inline const char *
  shape_name(const Shape s)
  {
    switch (s)
    {
      case Shape::random:
        return "random";
      case Shape::needle:
        return "needle";
      case Shape::sliver:
        return "sliver";
      case Shape::cap:
        return "cap";
      case Shape::wedge:
        return "wedge";
    }
    return "?";
  }

  inline std::array<Point, 4>
  make_tetrahedron(const Shape shape, std::mt19937 &rng)
  {
    std::uniform_real_distribution<double> u(-1, 1);
    std::array<Point, 4>                   x;
    switch (shape)
    {
      case Shape::random:
        do
          for (auto &p : x)
            p = {u(rng), u(rng), u(rng)};
        while (std::abs(volume(x[0], x[1], x[2], x[3])) < 0.05);
        break;
      case Shape::needle:
        x = {{{0, 0, 0}, {1e-2, 0, 0}, {0, 1e-2, 0}, {0.003, 0.003, 1.0}}};
        break;
      case Shape::sliver:
        x = {{{0, 0, 0}, {1, 1, 0}, {1, 0, 1e-3}, {0, 1, 1e-3}}};
        break;
      case Shape::cap:
        x = {{{0, 0, 0}, {1, 0, 0}, {0.5, 0.9, 0}, {0.5, 0.3, 1e-3}}};
        break;
      case Shape::wedge:
        x = {{{0, 0, 0}, {1e-2, 0, 0}, {0.5, 1, 0}, {0.5, 0, 1}}};
        break;
    }
    // A random rigid motion and scale, so that nothing is axis-aligned.
    if (shape != Shape::random)
    {
      const Point  axis  = normalized({u(rng), u(rng), u(rng)});
      const double angle = 3.0 * u(rng);
      const double s     = 0.5 + 0.5 * (u(rng) + 1);
      const Point  shift{u(rng), u(rng), u(rng)};
      for (auto &p : x)
      {
        const Point r =
          add(add(scale(std::cos(angle), p), scale(std::sin(angle), cross(axis, p))),
              scale((1 - std::cos(angle)) * dot(axis, p), axis));
        p = add(scale(s, r), shift);
      }
    }
    if (volume(x[0], x[1], x[2], x[3]) < 0)
      std::swap(x[0], x[1]);
    return x;
  }

  /**
   * A plane: points x with dot(normal, x - origin) = 0.
   */
  struct Plane
  {
    Point origin{};
    Point normal{};

    double
    operator()(const Point &x) const
    {
      return dot(normal, sub(x, origin));
    }
  };

  /**
   * A planar cut surface, possibly bounded by a straight crack front: the crack is the
   * part of the plane where front(x) < 0.
   */
  struct CutSurface
  {
    Plane plane;
    bool  has_front = false;
    Plane front;
    /** Identifies one cut across the steps that sweep it. */
    int id = 0;

    double
    behind(const Point &x) const
    {
      return has_front ? front(x) : -1.0;
    }
  };

  /**
   * A tetrahedral mesh on raw arrays; vertex ids are indices into points.
   */
  struct Mesh
  {
    std::vector<Point>                        points;
    std::vector<std::array<std::uint32_t, 4>> tets;
    /**
     * Points known to lie on the cut surface `surface` (snapped vertices keep that
     * status while the cut proceeds, and so do their copies), as a real cutter stores
     * it with the cut surface.
     */
    std::vector<bool> on_surface;
    int               surface = -1;
  };

  inline std::array<std::uint32_t, 3>
  sorted(std::uint32_t a, std::uint32_t b, std::uint32_t c)
  {
    std::array<std::uint32_t, 3> f{a, b, c};
    std::sort(f.begin(), f.end());
    return f;
  }

  /**
   * What the cutter decides globally before splitting: sides after snapping, cut edges
   * with their parameters, and front points per face; then one TetCut per affected
   * tetrahedron.
   */
  struct CutAnalysis
  {
    std::vector<std::int8_t>                                  side;
    std::vector<bool>                                         on_plane;
    std::map<std::pair<std::uint32_t, std::uint32_t>, double> edge_t;
    std::map<std::array<std::uint32_t, 3>, Point>             front_points;
    std::vector<std::size_t>                                  affected;
    std::vector<TetCut>                                       cuts;
  };

  inline CutAnalysis
  analyse(const Mesh &mesh, const CutSurface &surface, const double eps)
  {
    CutAnalysis       a;
    const auto       &x    = mesh.points;
    const std::size_t n    = x.size();
    double            size = 0;
    for (const auto &p : x)
      size = std::max({size, std::abs(p[0]), std::abs(p[1]), std::abs(p[2])});
    const double zero = 1e-12 * std::max(size, 1.0);

    std::vector<double> d(n);
    for (std::size_t v = 0; v < n; ++v)
    {
      d[v] = surface.plane(x[v]);
      if (std::abs(d[v]) <= zero)
        d[v] = 0;
    }
    std::set<std::pair<std::uint32_t, std::uint32_t>> edges;
    for (const auto &t : mesh.tets)
      for (const auto &e : tet_edge_vertices)
        edges.insert({std::min(t[e[0]], t[e[1]]), std::max(t[e[0]], t[e[1]])});

    // Snapping, once per mesh edge, from the whole plane (not only the part the crack
    // has reached): a crossing close to an end moves there. Deciding it from the final
    // surface makes a cut in many steps snap exactly as one stroke does. A snapped
    // vertex joins the cut when the crack reaches it; its edges are never cut.
    std::vector<bool> on_plane(n, false), reached(n, false);
    for (std::size_t v = 0; v < n; ++v)
    {
      on_plane[v] = d[v] == 0
                    || (mesh.surface == surface.id && v < mesh.on_surface.size()
                        && mesh.on_surface[v]);
      reached[v] = surface.behind(x[v]) < 0;
    }
    for (const auto &[i, j] : edges)
      if (d[i] * d[j] < 0)
      {
        const EdgeSnap s = snap_edge_parameter(d[i] / (d[i] - d[j]), eps);
        if (s == EdgeSnap::first_vertex)
          on_plane[i] = true;
        else if (s == EdgeSnap::second_vertex)
          on_plane[j] = true;
      }
    // The crack front must not cross an edge lying in the cut surface (the table puts
    // front points inside faces only): vertices on the surface joined by such edges are
    // reached as a group, when all of them are.
    {
      std::vector<std::size_t> group(n);
      std::iota(group.begin(), group.end(), 0);
      const auto find = [&](std::size_t i)
      {
        while (group[i] != i)
          i = group[i] = group[group[i]];
        return i;
      };
      for (const auto &[i, j] : edges)
        if (on_plane[i] && on_plane[j])
          group[find(i)] = find(j);
      std::vector<bool> all_reached(n, true);
      for (std::size_t v = 0; v < n; ++v)
        if (on_plane[v] && !reached[v])
          all_reached[find(v)] = false;
      for (std::size_t v = 0; v < n; ++v)
        if (on_plane[v])
          reached[v] = all_reached[find(v)];
    }
    a.side.resize(n);
    for (std::size_t v = 0; v < n; ++v)
      a.side[v] = on_plane[v] && reached[v] ? 0 : (d[v] >= 0 ? 1 : -1);
    a.on_plane = on_plane;

    // Section corners: vertices on the plane, and crossings of edges whose ends are both
    // off the plane. Cut edges are the reached crossings.
    std::map<std::pair<std::uint32_t, std::uint32_t>, bool> crossing_reached;
    for (const auto &[i, j] : edges)
      if (!on_plane[i] && !on_plane[j] && d[i] * d[j] < 0)
      {
        const double t           = d[i] / (d[i] - d[j]);
        const bool   is_cut      = surface.behind(lerp(x[i], x[j], t)) < 0;
        crossing_reached[{i, j}] = is_cut;
        if (is_cut)
          a.edge_t[{i, j}] = t;
      }

    // Front points, once per face, from the face's own two section corners.
    std::set<std::array<std::uint32_t, 3>> faces;
    for (const auto &t : mesh.tets)
      for (unsigned f = 0; f < 4; ++f)
        faces.insert(sorted(t[(f + 1) % 4], t[(f + 2) % 4], t[(f + 3) % 4]));
    if (surface.has_front)
      for (const auto &f : faces)
      {
        // The rule is the library's (the Cutter's): one implementation.
        std::array<SectionCorner, 6> corners;
        unsigned                     n_corners = 0, vertex_corners = 0;
        for (unsigned k = 0; k < 3; ++k)
          if (on_plane[f[k]])
          {
            corners[n_corners++] = {x[f[k]], x[f[k]], reached[f[k]]};
            ++vertex_corners;
          }
        for (unsigned k = 0; k < 3; ++k)
          for (unsigned l = k + 1; l < 3; ++l)
          {
            const auto it = crossing_reached.find({f[k], f[l]});
            if (it == crossing_reached.end())
              continue;
            const double t       = d[f[k]] / (d[f[k]] - d[f[l]]);
            const Point  p       = lerp(x[f[k]], x[f[l]], t);
            corners[n_corners++] = {p, p, it->second};
          }
        Point rest, now;
        if (front_point_on_face(
              corners.data(),
              n_corners,
              vertex_corners,
              [&](const Point &p) { return surface.behind(p); },
              eps,
              rest,
              now))
          a.front_points[f] = rest;
      }

    for (std::size_t k = 0; k < mesh.tets.size(); ++k)
    {
      const auto &t = mesh.tets[k];
      TetCut      c;
      bool        affected = false;
      for (unsigned v = 0; v < 4; ++v)
      {
        c.vertex_ids[v]  = t[v];
        c.points[v]      = x[t[v]];
        c.vertex_side[v] = a.side[t[v]];
        affected |= a.side[t[v]] == 0;
      }
      for (unsigned e = 0; e < 6; ++e)
      {
        const std::uint32_t i = t[tet_edge_vertices[e][0]],
                            j = t[tet_edge_vertices[e][1]];
        const auto it         = a.edge_t.find({std::min(i, j), std::max(i, j)});
        if (it != a.edge_t.end())
        {
          c.cut_edges |= static_cast<std::uint8_t>(1u << e);
          c.edge_parameter[e] = it->second;
          affected            = true;
        }
      }
      for (unsigned f = 0; f < 4; ++f)
      {
        const auto it =
          a.front_points.find(sorted(t[(f + 1) % 4], t[(f + 2) % 4], t[(f + 3) % 4]));
        if (it != a.front_points.end())
        {
          c.front_faces |= static_cast<std::uint8_t>(1u << f);
          c.front_points[f] = it->second;
          affected          = true;
        }
      }
      if (affected)
      {
        a.affected.push_back(k);
        a.cuts.push_back(c);
      }
    }
    return a;
  }

  struct CutStatistics
  {
    std::size_t split_tets  = 0;
    std::size_t children    = 0;
    std::size_t unsupported = 0;
    std::size_t partial     = 0;
  };

  /**
   * Applies one cut to the whole mesh: splits every affected tetrahedron, merges the new
   * points by key, and gives a vertex on the cut one copy per group of its tetrahedra
   * that stay connected through faces not on the cut.
   */
  inline CutStatistics
  cut_mesh(Mesh &mesh, const CutSurface &surface, const double eps)
  {
    CutStatistics                             stats;
    const CutAnalysis                         a = analyse(mesh, surface, eps);
    std::map<PointKey, std::uint32_t>         ids;
    std::vector<std::array<std::uint32_t, 4>> tets;
    std::vector<bool>                         replaced(mesh.tets.size(), false);
    std::vector<std::uint8_t>                 tet_cut_faces;
    std::vector<Point>                       &points = mesh.points;
    mesh.surface                                     = surface.id;
    mesh.on_surface                                  = a.on_plane;

    SplitResult r;
    for (std::size_t k = 0; k < a.cuts.size(); ++k)
    {
      const TetCut &c = a.cuts[k];
      if (split_tetrahedron(c, r, eps) == CutKind::unsupported)
      {
        ++stats.unsupported;
        continue;
      }
      replaced[a.affected[k]] = true;
      stats.partial += r.kind == CutKind::partial;
      ++stats.split_tets;
      stats.children += r.n_children;
      for (unsigned i = 0; i < r.n_children; ++i)
      {
        const Child                 &child = r.children[i];
        const auto                   p     = child_node_points(c, r, child);
        std::array<std::uint32_t, 4> t;
        for (unsigned j = 0; j < 4; ++j)
        {
          const NodeRef &n = child.nodes[j];
          if (n.kind == NodeKind::vertex)
          {
            t[j] = static_cast<std::uint32_t>(c.vertex_ids[n.index]);
            continue;
          }
          const PointKey key = point_key(c.vertex_ids, n, a.affected[k]);
          const auto     it  = ids.find(key);
          if (it != ids.end())
            t[j] = it->second;
          else
          {
            t[j] = static_cast<std::uint32_t>(points.size());
            points.push_back(p[j]);
            mesh.on_surface.push_back(n.kind != NodeKind::interior_point);
            ids.emplace(key, t[j]);
          }
        }
        tets.push_back(t);
        tet_cut_faces.push_back(child.cut_faces);
      }
    }
    for (std::size_t k = 0; k < mesh.tets.size(); ++k)
      if (!replaced[k])
      {
        tets.push_back(mesh.tets[k]);
        tet_cut_faces.push_back(0);
      }

    // Copies of vertices on the cut: one per connected group of incident tetrahedra.
    std::map<std::uint32_t, std::vector<std::size_t>> incident;
    for (std::size_t k = 0; k < tets.size(); ++k)
      for (const auto v : tets[k])
        if (v < a.side.size() && a.side[v] == 0)
          incident[v].push_back(k);
    // Which incident tetrahedra share a copy: the library's rule (the Cutter's).
    std::vector<StarCell>     star;
    std::vector<unsigned int> group;
    for (const auto &[v, list] : incident)
    {
      star.clear();
      for (const std::size_t k : list)
        star.push_back(
          {{tets[k][0], tets[k][1], tets[k][2], tets[k][3]}, tet_cut_faces[k]});
      const unsigned int         n_groups = separate_star(v, star, group);
      std::vector<std::uint32_t> copy(n_groups, v);
      for (unsigned int g = 1; g < n_groups; ++g)
      {
        copy[g] = static_cast<std::uint32_t>(points.size());
        points.push_back(points[v]);
        mesh.on_surface.push_back(true);
      }
      for (std::size_t i = 0; i < list.size(); ++i)
        for (auto &node : tets[list[i]])
          if (node == v)
            node = copy[group[i]];
    }
    mesh.tets = std::move(tets);
    return stats;
  }

  inline double
  mesh_volume(const Mesh &mesh)
  {
    double v = 0;
    for (const auto &t : mesh.tets)
      v += volume(mesh.points[t[0]],
                  mesh.points[t[1]],
                  mesh.points[t[2]],
                  mesh.points[t[3]]);
    return v;
  }

  inline double
  min_tet_volume(const Mesh &mesh)
  {
    double v = 1e300;
    for (const auto &t : mesh.tets)
      v = std::min(v,
                   volume(mesh.points[t[0]],
                          mesh.points[t[1]],
                          mesh.points[t[2]],
                          mesh.points[t[3]]));
    return v;
  }

  /**
   * Checks that the mesh is conforming: every face is shared by at most two
   * tetrahedra; a face of only one lies on the domain boundary (as told by
   * @p on_boundary) or on one of the cut @p planes; and these boundary faces close up
   * (every edge of theirs is used an even number of times). A hanging vertex leaves an
   * unmatched face inside or an odd boundary edge. The two sheets of a cut are separate
   * surfaces and need not be triangulated alike. Snapping moves the cut surface off the
   * plane, by up to @p tolerance. Returns an empty string if conforming, otherwise a
   * description of the first problem.
   */
  template <typename OnBoundary>
  std::string
  conformity_error(const Mesh               &mesh,
                   const OnBoundary         &on_boundary,
                   const std::vector<Plane> &planes,
                   const double              tolerance = 1e-9)
  {
    std::map<std::array<std::uint32_t, 3>, unsigned> count;
    for (const auto &t : mesh.tets)
      for (unsigned f = 0; f < 4; ++f)
        ++count[sorted(t[(f + 1) % 4], t[(f + 2) % 4], t[(f + 3) % 4])];
    std::map<std::pair<std::uint32_t, std::uint32_t>, unsigned> boundary_edges;
    for (const auto &[f, c] : count)
    {
      if (c > 2)
        return "face shared by more than two tetrahedra";
      if (c == 2)
        continue;
      const std::array<Point, 3> p{mesh.points[f[0]],
                                   mesh.points[f[1]],
                                   mesh.points[f[2]]};
      bool                       on_plane = on_boundary(p);
      for (const auto &plane : planes)
        on_plane =
          on_plane
          || (std::abs(plane(p[0])) <= tolerance && std::abs(plane(p[1])) <= tolerance
              && std::abs(plane(p[2])) <= tolerance);
      if (!on_plane)
      {
        std::ostringstream s;
        s << "unmatched interior face at (" << p[0][0] << "," << p[0][1] << "," << p[0][2]
          << ")";
        return s.str();
      }
      ++boundary_edges[{f[0], f[1]}];
      ++boundary_edges[{f[0], f[2]}];
      ++boundary_edges[{f[1], f[2]}];
    }
    for (const auto &[e, c] : boundary_edges)
      if (c % 2 != 0)
        return "boundary does not close up at an edge (hanging vertex?)";
    return {};
  }

  /**
   * Connected components of the mesh through shared faces: the volume of each.
   */
  inline std::vector<double>
  component_volumes(const Mesh &mesh)
  {
    std::vector<std::size_t> parent(mesh.tets.size());
    std::iota(parent.begin(), parent.end(), 0);
    const auto find = [&](std::size_t i)
    {
      while (parent[i] != i)
        i = parent[i] = parent[parent[i]];
      return i;
    };
    std::map<std::array<std::uint32_t, 3>, std::size_t> first;
    for (std::size_t k = 0; k < mesh.tets.size(); ++k)
      for (unsigned f = 0; f < 4; ++f)
      {
        const auto &t    = mesh.tets[k];
        const auto  face = sorted(t[(f + 1) % 4], t[(f + 2) % 4], t[(f + 3) % 4]);
        const auto [it, inserted] = first.emplace(face, k);
        if (!inserted)
          parent[find(k)] = find(it->second);
      }
    std::map<std::size_t, double> v;
    for (std::size_t k = 0; k < mesh.tets.size(); ++k)
    {
      const auto &t = mesh.tets[k];
      v[find(k)] += volume(mesh.points[t[0]],
                           mesh.points[t[1]],
                           mesh.points[t[2]],
                           mesh.points[t[3]]);
    }
    std::vector<double> result;
    for (const auto &[root, vol] : v)
      result.push_back(vol);
    std::sort(result.begin(), result.end());
    return result;
  }

  /**
   * A box [0,1]^3 of n^3 cubes, each split into six tetrahedra around its main
   * diagonal (a conforming Kuhn triangulation), with vertex ids shuffled so that the
   * global order has no relation to the geometry.
   */
  inline Mesh
  box_mesh(const unsigned n, std::mt19937 &rng)
  {
    Mesh       mesh;
    const auto index = [n](unsigned i, unsigned j, unsigned k)
    { return (k * (n + 1) + j) * (n + 1) + i; };
    std::vector<std::uint32_t> shuffle((n + 1) * (n + 1) * (n + 1));
    std::iota(shuffle.begin(), shuffle.end(), 0u);
    std::shuffle(shuffle.begin(), shuffle.end(), rng);
    mesh.points.resize(shuffle.size());
    for (unsigned k = 0; k <= n; ++k)
      for (unsigned j = 0; j <= n; ++j)
        for (unsigned i = 0; i <= n; ++i)
          mesh.points[shuffle[index(i, j, k)]] = {double(i) / n,
                                                  double(j) / n,
                                                  double(k) / n};
    // The six paths from corner (0,0,0) to (1,1,1) of the unit cube.
    const std::array<std::array<unsigned, 3>, 6> paths = {
      {{{0, 1, 2}}, {{0, 2, 1}}, {{1, 0, 2}}, {{1, 2, 0}}, {{2, 0, 1}}, {{2, 1, 0}}}};
    for (unsigned k = 0; k < n; ++k)
      for (unsigned j = 0; j < n; ++j)
        for (unsigned i = 0; i < n; ++i)
          for (const auto &path : paths)
          {
            std::array<unsigned, 3>      c{i, j, k};
            std::array<std::uint32_t, 4> t;
            t[0] = shuffle[index(c[0], c[1], c[2])];
            for (unsigned s = 0; s < 3; ++s)
            {
              ++c[path[s]];
              t[s + 1] = shuffle[index(c[0], c[1], c[2])];
            }
            const auto &x = mesh.points;
            if (volume(x[t[0]], x[t[1]], x[t[2]], x[t[3]]) < 0)
              std::swap(t[0], t[1]);
            mesh.tets.push_back(t);
          }
    return mesh;
  }

  /// box_mesh() as a TetMesh.
  inline mesh::TetMesh
  box_tet_mesh(const unsigned n, std::mt19937 &rng)
  {
    const auto                box = box_mesh(n, rng);
    std::vector<mesh::Point3> x(box.points.begin(), box.points.end());
    std::vector<mesh::Tet>    t;
    for (const auto &c : box.tets)
      t.push_back({{c[0], c[1], c[2], c[3]}});
    return mesh::TetMesh(x, t, "box");
  }

  /**
   * Whether three points lie on one face of the box [0,1]^3.
   */
  inline bool
  on_box_boundary(const std::array<Point, 3> &p)
  {
    for (unsigned k = 0; k < 3; ++k)
      for (const double w : {0.0, 1.0})
        if (p[0][k] == w && p[1][k] == w && p[2][k] == w)
          return true;
    return false;
  }

  /**
   * Moves @p cutter's blade through @p path in @p steps equal steps per segment,
   * calling @p after_step(segment, step, statistics of the step) after each; stops
   * when it returns false.
   */
  template <typename Function>
  void
  stroke(Cutter                   &cutter,
         const std::vector<Blade> &path,
         const unsigned int        steps,
         const Function           &after_step)
  {
    for (std::size_t k = 0; k + 1 < path.size(); ++k)
      for (unsigned int s = 1; s <= steps; ++s)
      {
        const double            f = double(s) / steps;
        const CutStepStatistics statistics =
          cutter.move_blade({lerp(path[k].tail, path[k + 1].tail, f),
                             lerp(path[k].head, path[k + 1].head, f)});
        if (!after_step(k, s, statistics))
          return;
      }
  }
} // namespace lacerta::cut::test_support
