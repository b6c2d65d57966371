#include <lacerta/base/archive.h>
#include <lacerta/base/exceptions.h>
#include <lacerta/cut/cut_record.h>

#include <algorithm>
#include <map>
#include <tuple>

namespace lacerta::cut
{
  std::array<unsigned int, 4>
  record_key(const TetCut &cut, const NodeRef &node)
  {
    std::array<unsigned int, 4> ids{};
    if (node.kind == NodeKind::interior_point)
    {
      for (unsigned int m = 0; m < 4; ++m)
        ids[m] = static_cast<unsigned int>(cut.vertex_ids[m]);
      std::sort(ids.begin(), ids.end());
    }
    else
    {
      const PointKey key = point_key(cut.vertex_ids, node, 0);
      for (unsigned int m = 0; m < 3; ++m)
        ids[m] = static_cast<unsigned int>(key.ids[m]);
    }
    return ids;
  }


  std::vector<std::vector<mesh::Tet>>
  recorded_children(const CutRecord &record)
  {
    // The particle of every new point, by its key (kind and sorted vertex ids).
    std::map<std::pair<NodeKind, std::array<unsigned int, 4>>, unsigned int> point_of;
    for (const auto &p : record.new_points)
      if (p.kind != NodeKind::vertex)
        point_of[{p.kind, p.ids}] = p.id;
    // The copy each child node on the cut uses: (split, child, node) -> vertex.
    std::map<std::tuple<unsigned int, unsigned int, unsigned int>, unsigned int> choice;
    for (const auto &c : record.vertex_choices)
      choice[{c.cut, c.child, c.node}] = c.used;

    std::vector<std::vector<mesh::Tet>> result(record.cuts.size());
    for (unsigned int k = 0; k < record.cuts.size(); ++k)
    {
      const TetCut &c = record.cuts[k];
      mesh::Tet     t;
      for (unsigned int i = 0; i < 4; ++i)
        t[i] = static_cast<unsigned int>(c.vertex_ids[i]);
      SplitResult r;
      split_tetrahedron(c, r, record.snap_fraction);
      for (unsigned int i = 0; i < r.n_children; ++i)
      {
        mesh::Tet child;
        for (unsigned int j = 0; j < 4; ++j)
        {
          const NodeRef &n = r.children[i].nodes[j];
          if (n.kind == NodeKind::vertex)
            child[j] = t[n.index];
          else
          {
            const std::array<unsigned int, 4> ids = record_key(c, n);
            const auto                        it  = point_of.find({n.kind, ids});
            if (it == point_of.end())
              throw_error("recorded_children: internal error, a point of split ",
                          k,
                          " has no recorded particle.");
            child[j] = it->second;
          }
          // A point on the cut: the copy the cutter gave this child.
          if (n.kind != NodeKind::vertex || c.vertex_side[n.index] == 0)
            if (const auto it = choice.find({k, i, j}); it != choice.end())
              child[j] = it->second;
        }
        result[k].push_back(child);
      }
    }
    return result;
  }


  void
  CutRecord::serialize(Archive &archive)
  {
    archive(cuts, snap_fraction, new_points, vertex_choices);
  }
} // namespace lacerta::cut
