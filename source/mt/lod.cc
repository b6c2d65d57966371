#include <lacerta/base/archive.h>
#include <lacerta/mt/lod.h>
#include <lacerta/mt/lod_query.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>

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
      , need_until(mt.n_nodes(), -std::numeric_limits<double>::infinity())
      , frontier_position(mt.n_nodes(), mesh::invalid_index)
      , check_at(mt.n_nodes(), 0)
  {
    // The children of each node, once each (a node's fine tetrahedra have about 12
    // destroyers but 3 distinct ones): evaluate() walks these lists.
    children_begin.reserve(mt.n_nodes() + 1);
    children_begin.push_back(0);
    for (std::uint32_t j = 0; j < mt.n_nodes(); ++j)
    {
      mt.for_each_fine(j,
                       [this](const std::uint32_t t)
                       {
                         if (const std::uint32_t c = this->mt->destroyer[t];
                             c != mesh::invalid_index
                             && std::find(children.begin() + children_begin.back(),
                                          children.end(),
                                          c)
                                  == children.end())
                           children.push_back(c);
                       });
      children_begin.push_back(static_cast<std::uint32_t>(children.size()));
    }
    applied[0] = 1;
    mt.for_each_fine(0, [this](const std::uint32_t t) { activate(t); });
  }


  void
  Lod::follow_cut(const std::uint32_t parent, const std::vector<std::uint32_t> &children)
  {
    position.resize(mt->n_tets(), mesh::invalid_index);
    if (!is_active(parent))
      return;
    deactivate(parent);
    for (const std::uint32_t t : children)
      activate(t);
  }


  void
  Lod::activate(const std::uint32_t t)
  {
    activations.push_back({t, +1});
    position[t] = static_cast<std::uint32_t>(active.size());
    active.push_back(t);
    ++active_fine[mt->creator[t]];
    update_frontier(mt->creator[t]);
    if (mt->destroyer[t] != mesh::invalid_index)
    {
      ++active_coarse[mt->destroyer[t]];
      update_frontier(mt->destroyer[t]);
    }
  }


  void
  Lod::deactivate(const std::uint32_t t)
  {
    activations.push_back({t, -1});
    const std::uint32_t last = active.back();
    active[position[t]]      = last;
    position[last]           = position[t];
    active.pop_back();
    position[t] = mesh::invalid_index;
    --active_fine[mt->creator[t]];
    update_frontier(mt->creator[t]);
    if (mt->destroyer[t] != mesh::invalid_index)
    {
      --active_coarse[mt->destroyer[t]];
      update_frontier(mt->destroyer[t]);
    }
  }


  bool
  Lod::on_frontier(const std::uint32_t j) const
  {
    return j != 0
           && (active_coarse[j] == mt->n_coarse(j) || active_fine[j] == mt->n_fine(j));
  }


  void
  Lod::update_frontier(const std::uint32_t j)
  {
    const bool in = frontier_position[j] != mesh::invalid_index;
    if (on_frontier(j) == in)
      return;
    if (!in)
    {
      frontier_position[j] = static_cast<std::uint32_t>(frontier.size());
      frontier.push_back(j);
      joined.push_back(j);
    }
    else
    {
      const std::uint32_t last       = frontier.back();
      frontier[frontier_position[j]] = last;
      frontier_position[last]        = frontier_position[j];
      frontier_position[j]           = mesh::invalid_index;
      frontier.pop_back();
    }
  }


  void
  Lod::schedule_check(const std::uint32_t j, const LodQuery &query)
  {
    evaluate(j, query);
    check_at[j] = need_until[j];
    if (std::isfinite(check_at[j]))
    {
      checks.push_back({check_at[j], j});
      std::push_heap(checks.begin(), checks.end(), std::greater<>());
    }
  }


  bool
  Lod::needs(const std::uint32_t j, const LodQuery &query)
  {
    evaluate(j, query);
    return need_value[j] != 0;
  }


  double
  Lod::bound_until(const std::uint32_t j, const LodQuery &query) const
  {
    const auto &b = mt->ball[j];
    return travel + query.focus_slack({{b[0], b[1], b[2]}}, b[3], mt->error[j]);
  }


  bool
  Lod::evaluate_own(const std::uint32_t j, const LodQuery &query)
  {
    need_stamp[j] = stamp;
    // A node a cut pinned (MultiTriangulation::cut_pin) keeps its state for good, and
    // so decides for its descendants: those of a node pinned undone cannot be applied,
    // those of a node pinned applied are free.
    if (const int pin = mt->pin(j); pin != 0)
    {
      need_value[j] = pin > 0;
      need_until[j] = std::numeric_limits<double>::infinity();
      return true;
    }
    // The bounds: neither j nor a descendant can fail where the query allows error[j]
    // over ball[j].
    const auto &b = mt->ball[j];
    if (!(mt->error[j] > query.minimum_error({{b[0], b[1], b[2]}}, b[3])))
    {
      need_value[j] = 0;
      need_until[j] = bound_until(j, query);
      return true;
    }
    // Past the bound, j is needed if its own fragments fail. If they do not, the
    // children decide, and the bound no longer matters: j stays unneeded however it
    // changes as long as its own test and its children's answers do not (the bound
    // is then worked out only if a child turns out needed).
    const auto        &o = mt->own_ball[j];
    const mesh::Point3 own_center{{o[0], o[1], o[2]}};
    need_until[j] = travel + query.focus_slack(own_center, o[3], mt->own_error[j]);
    need_value[j] = mt->own_error[j] > query.minimum_error(own_center, o[3]);
    if (need_value[j])
      need_until[j] = std::min(need_until[j], bound_until(j, query));
    // The root has no coarse fragment: it is always applied, whatever its children.
    return need_value[j] != 0 || j == 0;
  }


  void
  Lod::evaluate(const std::uint32_t j, const LodQuery &query)
  {
    if (known(j) || evaluate_own(j, query))
      return;
    // Depth first over the descendants whose bounds do not rule them out: j is needed
    // as soon as one child is, and then stays so while that child does and j's bound
    // allows; otherwise it is not, until the first of its own tests and its
    // children's answers can change (accumulated in need_until).
    auto &stack = evaluation_stack;
    stack.clear();
    stack.push_back({j, children_begin[j]});
    while (!stack.empty())
    {
      Visit &visit = stack.back();
      if (visit.next == children_begin[visit.node + 1])
      {
        // No child of the node is needed: neither is it.
        const std::uint32_t done = visit.node;
        stack.pop_back();
        if (!stack.empty())
        {
          const std::uint32_t parent = stack.back().node;
          need_until[parent]         = std::min(need_until[parent], need_until[done]);
        }
        continue;
      }
      const std::uint32_t c = children[visit.next++];
      if (!known(c) && !evaluate_own(c, query))
      {
        stack.push_back({c, children_begin[c]});
        continue;
      }
      if (need_value[c] == 0)
      {
        need_until[visit.node] = std::min(need_until[visit.node], need_until[c]);
        continue;
      }
      // c is needed: so is every node on the stack, for as long as c is and their
      // bounds allow.
      double until = need_until[c];
      while (!stack.empty())
      {
        const std::uint32_t a = stack.back().node;
        stack.pop_back();
        until         = std::min(until, bound_until(a, query));
        need_value[a] = 1;
        need_until[a] = until;
      }
    }
  }


  void
  Lod::toggle(const std::uint32_t j)
  {
    const bool apply = !applied[j];
    applied[j]       = apply;
    changed[j] ^= 1;
    changed_list.push_back(j);
    if (apply)
    {
      mt->for_each_coarse(j, [this](const std::uint32_t t) { deactivate(t); });
      mt->for_each_fine(j, [this](const std::uint32_t t) { activate(t); });
    }
    else
    {
      mt->for_each_fine(j, [this](const std::uint32_t t) { deactivate(t); });
      mt->for_each_coarse(j, [this](const std::uint32_t t) { activate(t); });
    }
  }


  bool
  Lod::extract(const LodQuery &query)
  {
    for (const std::uint32_t j : changed_list)
      changed[j] = 0;
    changed_list.clear();
    activations.clear();
    if (++stamp == 0)
    {
      std::fill(need_stamp.begin(), need_stamp.end(), 0);
      stamp = 1;
    }
    n_last_applied = n_last_undone = 0;

    // The frontier nodes whose need may have changed: all of them for a new query;
    // otherwise those that joined the frontier since their last test and those whose
    // slack the focus has travelled past (the others keep their need: they stay).
    std::vector<std::uint32_t> candidates;
    travel = query.focus_travel();
    if (query.identity() != query_identity || mt->n_cut_updates != cut_updates_seen)
    {
      query_identity   = query.identity();
      cut_updates_seen = mt->n_cut_updates;
      std::fill(need_until.begin(),
                need_until.end(),
                -std::numeric_limits<double>::infinity());
      candidates = frontier;
      checks.clear();
    }
    else
    {
      candidates = joined;
      while (!checks.empty() && checks.front().first <= travel)
      {
        const auto [at, j] = checks.front();
        std::pop_heap(checks.begin(), checks.end(), std::greater<>());
        checks.pop_back();
        if (check_at[j] == at && frontier_position[j] != mesh::invalid_index)
          candidates.push_back(j);
      }
    }
    joined.clear();
    std::vector<std::uint32_t> to_apply, to_undo;
    for (const std::uint32_t j : candidates)
    {
      if (frontier_position[j] == mesh::invalid_index)
        continue;
      if (active_coarse[j] == mt->n_coarse(j) && needs(j, query))
        to_apply.push_back(j);
      else if (active_fine[j] == mt->n_fine(j) && !needs(j, query))
        to_undo.push_back(j);
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
      mt->for_each_coarse(j,
                          [&](const std::uint32_t t)
                          {
                            const std::uint32_t p = mt->creator[t];
                            if (p != 0 && active_fine[p] == mt->n_fine(p)
                                && !needs(p, query))
                              to_undo.push_back(p);
                          });
    }
    while (!to_apply.empty())
    {
      const std::uint32_t j = to_apply.back();
      to_apply.pop_back();
      if (applied[j] || active_coarse[j] != mt->n_coarse(j))
        continue;
      toggle(j);
      ++n_last_applied;
      mt->for_each_fine(j,
                        [&](const std::uint32_t t)
                        {
                          const std::uint32_t c = mt->destroyer[t];
                          if (c != mesh::invalid_index
                              && active_coarse[c] == mt->n_coarse(c) && needs(c, query))
                            to_apply.push_back(c);
                        });
    }
    // Every frontier node is now stable (applicable ones not needed, undoable ones
    // needed); those tested or new in this call wait for their slack. Stale entries
    // are dropped when they outnumber the frontier.
    for (const std::uint32_t j : candidates)
      if (frontier_position[j] != mesh::invalid_index)
        schedule_check(j, query);
    for (const std::uint32_t j : joined)
      if (frontier_position[j] != mesh::invalid_index)
        schedule_check(j, query);
    joined.clear();
    if (checks.size() > 4 * frontier.size() + 1024)
    {
      std::vector<std::pair<double, std::uint32_t>> kept;
      for (const auto &entry : checks)
        if (check_at[entry.second] == entry.first
            && frontier_position[entry.second] != mesh::invalid_index)
          kept.push_back(entry);
      checks.swap(kept);
      std::make_heap(checks.begin(), checks.end(), std::greater<>());
    }
    return n_last_applied + n_last_undone > 0;
  }


  void
  Lod::last_swap(std::vector<std::uint32_t> &removed,
                 std::vector<std::uint32_t> &added) const
  {
    removed.clear();
    added.clear();
    std::vector<std::pair<std::uint32_t, int>> sorted = activations;
    std::sort(sorted.begin(), sorted.end());
    for (std::size_t i = 0; i < sorted.size();)
    {
      int         net = 0;
      std::size_t j   = i;
      for (; j < sorted.size() && sorted[j].first == sorted[i].first; ++j)
        net += sorted[j].second;
      if (net > 0)
        added.push_back(sorted[i].first);
      else if (net < 0)
        removed.push_back(sorted[i].first);
      i = j;
    }
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
    // The tet of a fragment that contains p, or the one p is least outside of.
    std::uint32_t         best = mesh::invalid_index;
    std::array<double, 4> best_coordinates{};
    double                best_minimum = -1e300;
    const auto            consider     = [&](const std::uint32_t t)
    {
      const auto   b = mt->barycentric(t, p);
      const double m = *std::min_element(b.begin(), b.end());
      if (m > best_minimum)
      {
        best_minimum     = m;
        best             = t;
        best_coordinates = b;
      }
    };
    // A vertex a cut created is never brought in: the cut's nodes are pinned.
    std::uint32_t j = mt->vertex_node[v];
    while (true)
    {
      // The coarse tets of j (which the collapse of its vertex created) tile its star.
      best_minimum = -1e300;
      mt->for_each_coarse(j, consider);
      // Its destroyer (j) was not applied before; if its creator was, it was active.
      const std::uint32_t parent = mt->creator[best];
      if (was_applied(parent))
        return {best, best_coordinates};
      j = parent;
    }
  }


  void
  Lod::serialize(Archive &archive, const LodQuery &query)
  {
    archive.section("level of detail");
    archive(applied, changed, changed_list, position, active, active_coarse, active_fine);
    archive(need_stamp, need_value, need_until, travel, children_begin, children);
    archive(frontier, frontier_position, joined, checks, check_at, cut_updates_seen);
    archive(stamp, n_last_applied, n_last_undone);
    // The identity of a query is that of an object of this process: what is kept is
    // whether the last extraction answered the query it is given now.
    bool     current = query_identity == query.identity();
    archive &current;
    if (archive.loading())
      query_identity = current ? query.identity() : 0;
  }
} // namespace lacerta::mt
