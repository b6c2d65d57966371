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
    // nodes in a small hash table (a sort of the faces was the most mispredicted code
    // of the update). The working arrays are kept per thread: the cutter calls this
    // for every vertex on the cut, and should not allocate.
    static thread_local std::vector<std::size_t> parent;
    parent.resize(star.size());
    std::iota(parent.begin(), parent.end(), 0);
    const auto find = [&](std::size_t i)
    {
      while (parent[i] != i)
        i = parent[i] = parent[parent[i]];
      return i;
    };
    // One entry per distinct face: its first cell, and whether any of its cells has it
    // on the cut. The groups follow from which cells are joined, not from the order
    // of the joins, so the result is that of any grouping of equal faces.
    struct FaceGroup
    {
      std::uint64_t a, b;
      std::size_t   first_cell;
      bool          used, cut;
    };
    static thread_local std::vector<FaceGroup>   table;
    static thread_local std::vector<std::size_t> face_cell, face_group;
    face_cell.clear();
    face_group.clear();
    unsigned int bits = 4;
    while ((std::size_t(1) << bits) < 8 * star.size())
      ++bits;
    const std::size_t mask = (std::size_t(1) << bits) - 1;
    table.assign(mask + 1, {0, 0, 0, false, false});
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
        const std::uint64_t a = std::min(other[0], other[1]),
                            b = std::max(other[0], other[1]);
        // At most three faces per cell: the table, with room for eight, never fills.
        std::size_t h =
          (a * 0x9E3779B97F4A7C15ULL + b * 0xC2B2AE3D27D4EB4FULL) >> (64 - bits);
        while (table[h].used & ((table[h].a != a) | (table[h].b != b)))
          h = (h + 1) & mask;
        FaceGroup &g = table[h];
        // Selects, not branches: whether the face was seen follows no pattern.
        g.first_cell = g.used ? g.first_cell : i;
        g.cut        = g.cut | ((star[i].cut_faces & (1u << j)) != 0);
        g.a          = a;
        g.b          = b;
        g.used       = true;
        face_cell.push_back(i);
        face_group.push_back(h);
      }
    }
    for (std::size_t f = 0; f < face_cell.size(); ++f)
    {
      const FaceGroup &g = table[face_group[f]];
      if (!g.cut)
        parent[find(face_cell[f])] = find(g.first_cell);
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
