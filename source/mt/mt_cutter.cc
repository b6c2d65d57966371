#include <lacerta/base/archive.h>
#include <lacerta/base/exceptions.h>
#include <lacerta/mt/mt_cutter.h>

#include <algorithm>
#include <chrono>

namespace lacerta::mt
{
  MtCutter::MtCutter(MultiTriangulation &mt_in)
      : mt(mt_in)
  {
    vertex_tets.resize(mt.n_vertices());
    for (std::uint32_t t = 0; t < mt.n_tets(); ++t)
      if (mt.is_live(t))
        for (const auto v : mt.tets[t])
          vertex_tets.insert(v, t);
  }


  std::uint32_t
  MtCutter::find_tet(const mesh::Tet &ids, const Lod &lod) const
  {
    mesh::Tet sorted = ids;
    std::sort(sorted.begin(), sorted.end());
    for (const std::uint32_t t : vertex_tets[sorted[0]])
    {
      if (!mt.is_live(t) || !lod.is_active(t))
        continue;
      mesh::Tet candidate = mt.tets[t];
      std::sort(candidate.begin(), candidate.end());
      if (candidate == sorted)
        return t;
    }
    throw_error("MtCutter: internal error, a tetrahedron the cutter replaced (MT "
                "vertices ",
                ids[0],
                ", ",
                ids[1],
                ", ",
                ids[2],
                ", ",
                ids[3],
                ") is not active in the level of detail that was cut.");
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


  void
  MtCutter::pin(const std::uint32_t parent, Statistics &statistics)
  {
    // A node must be applied with its parents (the creators of its coarse tets) and
    // stays undone with its children (the destroyers of its fine tets). The walks stop
    // at nodes pinned already, whose ancestors (descendants) are pinned too.
    std::vector<std::uint32_t> stack;
    const auto                 walk = [&](const std::uint32_t start, const int value)
    {
      stack.assign(1, start);
      while (!stack.empty())
      {
        const std::uint32_t j = stack.back();
        stack.pop_back();
        if (mt.cut_pin[j] == value)
          continue;
        if (mt.cut_pin[j] != 0)
          throw_error("MtCutter: internal error, node ",
                      j,
                      " must be applied and undone at once: the records were not made "
                      "on a level of detail of this MT.");
        mt.cut_pin[j] = static_cast<std::int8_t>(value);
        ++(value > 0 ? statistics.pinned_applied : statistics.pinned_undone);
        const auto push = [&](const std::uint32_t node)
        {
          if (node != mesh::invalid_index && mt.cut_pin[node] != value)
            stack.push_back(node);
        };
        if (value > 0)
          mt.for_each_coarse(j, [&](const std::uint32_t t) { push(mt.creator[t]); });
        else
          mt.for_each_fine(j, [&](const std::uint32_t t) { push(mt.destroyer[t]); });
      }
    };
    walk(mt.creator[parent], +1);
    if (mt.destroyer[parent] != mesh::invalid_index)
      walk(mt.destroyer[parent], -1);
  }


  MtCutter::Statistics
  MtCutter::apply(const std::vector<cut::CutRecord> &records,
                  std::vector<std::uint32_t>        &mt_vertex_of,
                  Lod                               &lod)
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
    if (mt.cut_pin.empty())
      mt.cut_pin.assign(mt.n_nodes(), 0);

    std::vector<std::uint32_t> fragments, ids;
    for (const cut::CutRecord &record : records)
    {
      // The particles the sweep created become MT vertices, in the cutter's order.
      const std::size_t first_new = mt.vertices.size();
      for (const auto &p : record.new_points)
      {
        if (p.id != mt_vertex_of.size())
          throw_error("MtCutter: internal error, the cutter's particle ",
                      p.id,
                      " does not follow the ",
                      mt_vertex_of.size(),
                      " vertices the MT knows of the cut mesh.");
        mt_vertex_of.push_back(mt.n_vertices());
        mt.vertices.push_back(p.position);
        mt.vertex_node.push_back(0);
        mt.cut_origin.push_back(mesh::invalid_index);
        ++statistics.new_vertices;
      }
      vertex_tets.resize(mt.n_vertices());
      const auto to_mt = [&](const unsigned int v)
      {
        if (v >= mt_vertex_of.size())
          throw_error("MtCutter: internal error, cut mesh vertex ", v, " is unknown.");
        return mt_vertex_of[v];
      };

      const std::vector<std::vector<mesh::Tet>> children = cut::recorded_children(record);
      for (std::size_t k = 0; k < record.cuts.size(); ++k)
      {
        mesh::Tet parent_ids;
        for (unsigned int i = 0; i < 4; ++i)
          parent_ids[i] = to_mt(static_cast<unsigned int>(record.cuts[k].vertex_ids[i]));
        const std::uint32_t parent = find_tet(parent_ids, lod);
        ids.clear();
        for (const mesh::Tet &child : children[k])
        {
          mesh::Tet tet;
          for (unsigned int j = 0; j < 4; ++j)
          {
            tet[j] = to_mt(child[j]);
            // A new vertex belongs to the fragment of the first tet it appears in.
            if (tet[j] >= first_new
                && mt.cut_origin[tet[j] - mt.first_cut_vertex()] == mesh::invalid_index)
            {
              mt.cut_origin[tet[j] - mt.first_cut_vertex()] = parent;
              mt.vertex_node[tet[j]]                        = mt.creator[parent];
            }
          }
          const auto id = static_cast<std::uint32_t>(mt.tets.size());
          mt.tets.push_back(tet);
          mt.creator.push_back(mt.creator[parent]);
          mt.destroyer.push_back(mt.destroyer[parent]);
          mt.replaced.push_back(0);
          for (const auto v : tet)
            vertex_tets.insert(v, id);
          ids.push_back(id);
        }
        mt.replaced[parent] = 1;
        replace_in_fragments(parent, ids);
        lod.follow_cut(parent, ids);
        pin(parent, statistics);
        fragments.push_back(mt.creator[parent]);
        ++statistics.cut_tets;
        statistics.created_tets += static_cast<unsigned int>(ids.size());
      }
      for (std::size_t v = first_new; v < mt.vertices.size(); ++v)
        if (mt.cut_origin[v - mt.first_cut_vertex()] == mesh::invalid_index)
          throw_error("MtCutter: internal error, the cutter's particle of MT vertex ",
                      v,
                      " is in none of the children it recorded.");
    }
    if (!records.empty())
      ++mt.n_cut_updates;
    std::sort(fragments.begin(), fragments.end());
    statistics.split_fragments = static_cast<unsigned int>(
      std::unique(fragments.begin(), fragments.end()) - fragments.begin());
    statistics.seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return statistics;
  }


  void
  MtCutter::serialize(Archive &archive)
  {
    archive &vertex_tets;
  }
} // namespace lacerta::mt
