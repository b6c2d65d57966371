#include <lacerta/cut/cut_rules.h>
#include <lacerta/cut/geometry.h>

#include <algorithm>
#include <numeric>

namespace lacerta::cut
{
  bool
  front_point_on_face(const SectionCorner                        *corners,
                      const unsigned int                          n_corners,
                      const unsigned int                          n_vertex_corners,
                      const std::function<double(const Point &)> &behind,
                      const double                                snap_fraction,
                      Point                                      &rest,
                      Point                                      &now)
  {
    if (n_corners != 2 || corners[0].reached == corners[1].reached
        || n_vertex_corners == 2)
      return false;
    const SectionCorner &r  = corners[0].reached ? corners[0] : corners[1];
    const SectionCorner &u  = corners[0].reached ? corners[1] : corners[0];
    const double         pr = behind(r.now), pu = behind(u.now);
    const double         s = clamp_front_parameter(pr / (pr - pu), snap_fraction);
    rest                   = lerp(r.rest, u.rest, s);
    now                    = lerp(r.now, u.now, s);
    return true;
  }


  unsigned int
  separate_star(const std::uint64_t          v,
                const std::vector<StarCell> &star,
                std::vector<unsigned int>   &group)
  {
    // Union-find over the cells; the faces through v are matched by their two other
    // nodes (sorted), so no map is needed. The working arrays are kept per thread:
    // the cutter calls this for every vertex on the cut, and should not allocate.
    static thread_local std::vector<std::size_t> parent;
    parent.resize(star.size());
    std::iota(parent.begin(), parent.end(), 0);
    const auto find = [&](std::size_t i)
    {
      while (parent[i] != i)
        i = parent[i] = parent[parent[i]];
      return i;
    };
    struct FaceRef
    {
      std::uint64_t a, b;
      std::size_t   cell;
      bool          cut;
    };
    static thread_local std::vector<FaceRef> faces;
    faces.clear();
    for (std::size_t i = 0; i < star.size(); ++i)
    {
      const auto &n = star[i].nodes;
      for (unsigned int j = 0; j < 4; ++j)
      {
        if (n[j] == v)
          continue;
        std::uint64_t other[2];
        unsigned int  k = 0;
        for (unsigned int m = 0; m < 4; ++m)
          if (m != j && n[m] != v)
            other[k++] = n[m];
        if (k != 2)
          continue;
        faces.push_back({std::min(other[0], other[1]),
                         std::max(other[0], other[1]),
                         i,
                         (star[i].cut_faces & (1u << j)) != 0});
      }
    }
    std::sort(faces.begin(),
              faces.end(),
              [](const FaceRef &x, const FaceRef &y)
              { return x.a != y.a ? x.a < y.a : x.b < y.b; });
    for (std::size_t b = 0; b < faces.size();)
    {
      std::size_t e   = b;
      bool        cut = false;
      while (e < faces.size() && faces[e].a == faces[b].a && faces[e].b == faces[b].b)
      {
        cut = cut || faces[e].cut;
        ++e;
      }
      if (!cut)
        for (std::size_t i = b + 1; i < e; ++i)
          parent[find(faces[i].cell)] = find(faces[b].cell);
      b = e;
    }
    group.assign(star.size(), 0);
    static thread_local std::vector<std::size_t> roots;
    roots.clear();
    for (std::size_t i = 0; i < star.size(); ++i)
    {
      const std::size_t root = find(i);
      const auto        it   = std::find(roots.begin(), roots.end(), root);
      group[i]               = static_cast<unsigned int>(it - roots.begin());
      if (it == roots.end())
        roots.push_back(root);
    }
    return static_cast<unsigned int>(roots.size());
  }


  std::array<Point, 4>
  child_node_points(const TetCut &cut, const SplitResult &result, const Child &child)
  {
    std::array<Point, 4> p;
    for (unsigned int k = 0; k < 4; ++k)
    {
      const NodeRef &n = child.nodes[k];
      switch (n.kind)
      {
        case NodeKind::vertex:
          p[k] = cut.points[n.index];
          break;
        case NodeKind::edge_point:
          p[k] = result.edge_points[n.index];
          break;
        case NodeKind::face_point:
          p[k] = result.face_points[n.index];
          break;
        case NodeKind::interior_point:
          p[k] = result.interior_point;
          break;
      }
    }
    return p;
  }
} // namespace lacerta::cut
