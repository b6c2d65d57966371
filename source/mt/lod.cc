#include <lacerta/mt/lod.h>
#include <lacerta/mt/lod_query.h>

#include <algorithm>

namespace lacerta::mt
{
  Lod::Lod(const MultiTriangulation &mt)
      : mt(&mt)
      , applied(mt.n_nodes(), 0)
      , changed(mt.n_nodes(), 0)
      , position(mt.n_tets(), mesh::invalid_index)
      , active_coarse(mt.n_nodes(), 0)
      , active_fine(mt.n_nodes(), 0)
      , need_stamp(mt.n_nodes(), 0)
      , need_value(mt.n_nodes(), 0)
  {
    applied[0] = 1;
    for (std::uint32_t t = mt.fine_begin[0]; t < mt.fine_begin[1]; ++t)
      activate(t);
  }


  void
  Lod::activate(const std::uint32_t t)
  {
    position[t] = static_cast<std::uint32_t>(active.size());
    active.push_back(t);
    ++active_fine[mt->creator[t]];
    if (mt->destroyer[t] != mesh::invalid_index)
      ++active_coarse[mt->destroyer[t]];
  }


  void
  Lod::deactivate(const std::uint32_t t)
  {
    const std::uint32_t last = active.back();
    active[position[t]]      = last;
    position[last]           = position[t];
    active.pop_back();
    position[t] = mesh::invalid_index;
    --active_fine[mt->creator[t]];
    if (mt->destroyer[t] != mesh::invalid_index)
      --active_coarse[mt->destroyer[t]];
  }


  bool
  Lod::needs(const std::uint32_t j, const LodQuery &query)
  {
    if (need_stamp[j] != stamp)
    {
      const auto &b = mt->ball[j];
      need_stamp[j] = stamp;
      need_value[j] = mt->error[j] > query.minimum_error({{b[0], b[1], b[2]}}, b[3]);
    }
    return need_value[j] != 0;
  }


  void
  Lod::toggle(const std::uint32_t j)
  {
    const bool apply = !applied[j];
    applied[j]       = apply;
    changed[j] ^= 1;
    changed_list.push_back(j);
    const auto fine_begin = mt->fine_begin[j], fine_end = mt->fine_begin[j + 1];
    const auto coarse_begin = mt->coarse_list.begin() + mt->coarse_begin[j];
    const auto coarse_end   = mt->coarse_list.begin() + mt->coarse_begin[j + 1];
    if (apply)
    {
      std::for_each(coarse_begin, coarse_end, [this](auto t) { deactivate(t); });
      for (std::uint32_t t = fine_begin; t < fine_end; ++t)
        activate(t);
    }
    else
    {
      for (std::uint32_t t = fine_begin; t < fine_end; ++t)
        deactivate(t);
      std::for_each(coarse_begin, coarse_end, [this](auto t) { activate(t); });
    }
  }


  bool
  Lod::extract(const LodQuery &query)
  {
    for (const std::uint32_t j : changed_list)
      changed[j] = 0;
    changed_list.clear();
    if (++stamp == 0)
    {
      std::fill(need_stamp.begin(), need_stamp.end(), 0);
      stamp = 1;
    }
    n_last_applied = n_last_undone = 0;

    // The frontier: nodes whose coarse fragment is all active (can be applied) and
    // applied nodes whose fine fragment is all active (can be undone). Every active tet
    // points to one of each kind.
    std::vector<std::uint32_t> to_apply, to_undo;
    for (const std::uint32_t t : active)
    {
      const std::uint32_t d = mt->destroyer[t], c = mt->creator[t];
      if (d != mesh::invalid_index && active_coarse[d] == mt->n_coarse(d)
          && needs(d, query))
        to_apply.push_back(d);
      if (c != 0 && active_fine[c] == mt->n_fine(c) && !needs(c, query))
        to_undo.push_back(c);
    }
    // Undo first: a node without need has no descendant with need, so nothing undone
    // here is a parent of a node applied below.
    while (!to_undo.empty())
    {
      const std::uint32_t j = to_undo.back();
      to_undo.pop_back();
      if (!applied[j] || active_fine[j] != mt->n_fine(j))
        continue;
      toggle(j);
      ++n_last_undone;
      for (std::uint32_t k = mt->coarse_begin[j]; k < mt->coarse_begin[j + 1]; ++k)
      {
        const std::uint32_t p = mt->creator[mt->coarse_list[k]];
        if (p != 0 && active_fine[p] == mt->n_fine(p) && !needs(p, query))
          to_undo.push_back(p);
      }
    }
    while (!to_apply.empty())
    {
      const std::uint32_t j = to_apply.back();
      to_apply.pop_back();
      if (applied[j] || active_coarse[j] != mt->n_coarse(j))
        continue;
      toggle(j);
      ++n_last_applied;
      for (std::uint32_t t = mt->fine_begin[j]; t < mt->fine_begin[j + 1]; ++t)
      {
        const std::uint32_t c = mt->destroyer[t];
        if (c != mesh::invalid_index && active_coarse[c] == mt->n_coarse(c)
            && needs(c, query))
          to_apply.push_back(c);
      }
    }
    return n_last_applied + n_last_undone > 0;
  }


  std::vector<std::uint32_t>
  Lod::active_vertices() const
  {
    std::vector<std::uint32_t> vertices;
    vertices.reserve(active.size());
    for (const std::uint32_t t : active)
      vertices.insert(vertices.end(), mt->tets[t].begin(), mt->tets[t].end());
    std::sort(vertices.begin(), vertices.end());
    vertices.erase(std::unique(vertices.begin(), vertices.end()), vertices.end());
    return vertices;
  }


  mesh::TetMesh
  Lod::make_mesh(const std::vector<std::uint32_t> &vertices,
                 const std::string                &name) const
  {
    std::vector<mesh::Point3> points(vertices.size());
    for (std::size_t i = 0; i < vertices.size(); ++i)
      points[i] = mt->vertices[vertices[i]];
    // Sorted by tet id so that the mesh does not depend on the order of the updates.
    std::vector<std::uint32_t> sorted = active;
    std::sort(sorted.begin(), sorted.end());
    std::vector<mesh::Tet> cells(sorted.size());
    for (std::size_t i = 0; i < sorted.size(); ++i)
      for (unsigned int k = 0; k < 4; ++k)
        cells[i][k] = static_cast<unsigned int>(
          std::lower_bound(vertices.begin(), vertices.end(), mt->tets[sorted[i]][k])
          - vertices.begin());
    return mesh::TetMesh(std::move(points), std::move(cells), name);
  }


  std::pair<std::uint32_t, std::array<double, 4>>
  Lod::locate_in_previous(const std::uint32_t v) const
  {
    const mesh::Point3 &p = mt->vertices[v];
    std::uint32_t       j = mt->vertex_node[v];
    while (true)
    {
      // The coarse tets of j (which the collapse of its vertex created) tile its star;
      // take the one that contains p, or the one p is least outside of.
      std::uint32_t         best = mesh::invalid_index;
      std::array<double, 4> best_coordinates{};
      double                best_minimum = -1e300;
      for (std::uint32_t k = mt->coarse_begin[j]; k < mt->coarse_begin[j + 1]; ++k)
      {
        const std::uint32_t t = mt->coarse_list[k];
        const auto          b = mt->barycentric(t, p);
        const double        m = *std::min_element(b.begin(), b.end());
        if (m > best_minimum)
        {
          best_minimum     = m;
          best             = t;
          best_coordinates = b;
        }
      }
      // Its destroyer (j) was not applied before; if its creator was, it was active.
      const std::uint32_t parent = mt->creator[best];
      if (was_applied(parent))
        return {best, best_coordinates};
      j = parent;
    }
  }
} // namespace lacerta::mt
