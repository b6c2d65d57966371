/**
 * @file
 * A level of detail of a Multi-Triangulation: extraction by a query, incremental
 * update, and the location of new vertices in the previous level (Section 4.2).
 */
#pragma once

#include <lacerta/mesh/tet_mesh.h>
#include <lacerta/mt/multi_triangulation.h>

#include <array>
#include <cstdint>
#include <vector>

namespace lacerta
{
  class Archive;
}
namespace lacerta::mt
{
  class LodQuery;

  /**
   * The current level of detail: the set of applied nodes (closed under parents) and
   * the tetrahedra it selects.
   *
   * A node *fails* the query when its own error exceeds the smallest error the query
   * allows over its own ball (MultiTriangulation::own_error, own_ball): its coarse
   * tetrahedra are too coarse there. Node j must be applied when it or one of its
   * descendants fails; this predicate is closed under parents, so the applied set is
   * exactly the nodes that satisfy it: the smallest set closed under parents that
   * contains every failing node, the conforming mesh with the fewest tetrahedra that
   * refines every failing fragment. The same set comes out whether it is extracted
   * from the root or updated from any previous level of detail. The search of the
   * descendants is cut short by the monotone bounds (error, ball) of the MT.
   * Nodes a cut pinned (MultiTriangulation::cut_pin) are needed or not whatever the
   * query, so every extraction keeps the cut tetrahedra.
   */
  class Lod
  {
  public:
    /// Starts at the root (the coarsest mesh).
    explicit Lod(const MultiTriangulation &mt);

    /**
     * Updates to the level of detail @p query asks for, starting from the current one.
     * Only the frontier nodes (those that can be applied or undone) can start a change;
     * each one is tested again only once the focus has travelled the query's
     * focus_slack() for it, so the work is proportional to the nodes near the edge of
     * their need plus the nodes applied or undone, not to the current mesh nor the MT.
     * Given another query object than last time, every frontier node is tested.
     * Returns whether anything changed.
     */
    bool
    extract(const LodQuery &query);

    /// The active tetrahedra (ids into the MT), in no particular order.
    const std::vector<std::uint32_t> &
    active_tets() const
    {
      return active;
    }

    /// Whether tet @p t is active.
    bool
    is_active(const std::uint32_t t) const
    {
      return position[t] != mesh::invalid_index;
    }

    /// Whether node @p j is applied.
    bool
    is_applied(const std::uint32_t j) const
    {
      return applied[j] != 0;
    }

    /// Whether node @p j was applied before the last extract().
    bool
    was_applied(const std::uint32_t j) const
    {
      return (applied[j] != 0) != (changed[j] != 0);
    }

    /// Number of nodes applied and undone by the last extract().
    std::array<unsigned int, 2>
    last_change() const
    {
      return {{n_last_applied, n_last_undone}};
    }

    /**
     * What the last extract() changed: the MT tetrahedra that were active before it
     * and are not now, into @p removed, and those active now and not before, into
     * @p added, each sorted (a tetrahedron that came and went within the extraction is
     * in neither).
     */
    void
    last_swap(std::vector<std::uint32_t> &removed,
              std::vector<std::uint32_t> &added) const;

    /// The vertices of the active tetrahedra, sorted.
    std::vector<std::uint32_t>
    active_vertices() const;

    /**
     * The active mesh with its vertices numbered in the order of @p vertices (which
     * must be active_vertices()); @p name is used in messages.
     */
    mesh::TetMesh
    make_mesh(const std::vector<std::uint32_t> &vertices, const std::string &name) const;

    /**
     * Follows a cut (MtCutter) that replaced MT tet @p parent by @p children: if the
     * parent was active, the children are now. Call after the MT's fragments changed.
     */
    void
    follow_cut(std::uint32_t parent, const std::vector<std::uint32_t> &children);

    /**
     * For a vertex @p v that the last extract() brought in (never one a cut created:
     * the cut's nodes are pinned), the tetrahedron of the previous level of detail
     * that contains its rest position, found by walking up the MT from the fragment
     * that removed it (Section 4.2), and v's barycentric
     * coordinates in it (not clamped: slightly negative ones mean that v lies outside
     * the previous, coarser boundary).
     */
    std::pair<std::uint32_t, std::array<double, 4>>
    locate_in_previous(std::uint32_t v) const;

    /**
     * Writes or reads the state for a checkpoint (see lacerta::Archive); @p query is
     * the query of the last extraction, whose identity the loaded state keeps.
     */
    void
    serialize(Archive &archive, const LodQuery &query);

  private:
    void
    activate(std::uint32_t t);

    void
    deactivate(std::uint32_t t);

    bool
    needs(std::uint32_t j, const LodQuery &query);

    /// Whether the answer of needs() for node @p j is known and still valid:
    /// computed in this extraction, or earlier with a slack the focus has not
    /// travelled yet (need_until is reset when the query object changes).
    bool
    known(const std::uint32_t j) const
    {
      return need_stamp[j] == stamp || travel < need_until[j];
    }

    /// Computes needs() for node @p j and the descendants it depends on, with the
    /// travel of the focus up to which each answer holds.
    void
    evaluate(std::uint32_t j, const LodQuery &query);

    /**
     * Starts the evaluation of node @p j from its own tests: returns true when they
     * decide (then need_value and need_until are set), false when its children must
     * be looked at (need_until holds the bound from its own test).
     */
    bool
    evaluate_own(std::uint32_t j, const LodQuery &query);

    /// The focus travel up to which the monotone bound of node @p j (error, ball)
    /// keeps its answer.
    double
    bound_until(std::uint32_t j, const LodQuery &query) const;

    void
    toggle(std::uint32_t j);

    /// Whether node @p j can be applied (its coarse fragment is all active) or undone
    /// (its fine fragment is): only such nodes can start a change.
    bool
    on_frontier(std::uint32_t j) const;

    /// Adds node @p j to or removes it from the frontier after a counter changed.
    void
    update_frontier(std::uint32_t j);

    /// Queues frontier node @p j for a new test once the focus has travelled past
    /// its slack.
    void
    schedule_check(std::uint32_t j, const LodQuery &query);

    const MultiTriangulation  *mt;
    std::vector<std::uint8_t>  applied;
    std::vector<std::uint8_t>  changed;
    std::vector<std::uint32_t> changed_list;
    std::vector<std::uint32_t> position;
    std::vector<std::uint32_t> active;
    std::vector<std::uint32_t> active_coarse;
    std::vector<std::uint32_t> active_fine;
    std::vector<std::uint32_t> need_stamp;
    std::vector<std::uint8_t>  need_value;
    /// Per node: the focus travel up to which need_value holds (see known()).
    std::vector<double> need_until;
    /// The focus travel at this extraction.
    double travel = 0;
    /// The children of node j (the destroyers of its fine tetrahedra, each once):
    /// children[children_begin[j] .. children_begin[j + 1]).
    std::vector<std::uint32_t> children_begin, children;
    /// A node whose children evaluate() is looking at.
    struct Visit
    {
      std::uint32_t node;
      /// Where it is in its list of children.
      std::uint32_t next;
    };
    /// Scratch of evaluate().
    std::vector<Visit> evaluation_stack;
    /// The frontier nodes, with each node's place in it (invalid_index: not in it).
    std::vector<std::uint32_t> frontier;
    std::vector<std::uint32_t> frontier_position;
    /// Nodes that joined the frontier since their last test.
    std::vector<std::uint32_t> joined;
    /// Frontier tests due: (focus travel at which to test again, node), a min-heap;
    /// an entry is stale unless check_at[node] still holds its travel.
    std::vector<std::pair<double, std::uint32_t>> checks;
    std::vector<double>                           check_at;
    std::uint64_t                                 query_identity = 0;
    /// MultiTriangulation::n_cut_updates at the last extraction.
    unsigned int  cut_updates_seen = 0;
    std::uint32_t stamp            = 0;
    unsigned int  n_last_applied   = 0;
    unsigned int  n_last_undone    = 0;
    /// The tetrahedra activate() (+1) and deactivate() (-1) changed since the last
    /// extract() began, in order (last_swap()).
    std::vector<std::pair<std::uint32_t, int>> activations;
  };
} // namespace lacerta::mt
