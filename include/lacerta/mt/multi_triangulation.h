/**
 * @file
 * The Multi-Triangulation (Section 4): the fragments of a decimation and their DAG.
 */
#pragma once

#include <lacerta/mesh/tet_mesh.h>

#include <array>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace lacerta
{
  class Archive;
}
namespace lacerta::mt
{
  /**
   * A Multi-Triangulation built by decimation, stored in the refinement direction.
   *
   * Node 0 is the root: it inserts the tetrahedra of the fully decimated mesh. Every
   * other node j undoes one half-edge collapse: it removes the tetrahedra the collapse
   * created (its coarse fragment, coarse_tets(j)) and inserts the ones the collapse
   * removed (its fine fragment, the tets [fine_begin[j], fine_begin[j+1])), which brings
   * back vertex node_vertex[j]. Node j depends on the nodes that insert its coarse
   * tetrahedra (its parents), which always have smaller indices, so node order is a
   * topological order of the DAG. A set of applied nodes closed under parents gives a
   * conforming mesh: the tets whose creator is applied and whose destroyer is not.
   *
   * Vertices are those of the input mesh with their ids: decimation removes vertices and
   * never invents any, so particles keep their vertex id at every level of detail. A
   * cut (mt/mt_cutter.h) replaces the tetrahedra of the level of detail it cut by
   * their children, which keep their parent's creator and destroyer, appends the
   * vertices it creates, and pins the nodes (cut_pin) so that every later extraction
   * keeps those children.
   */
  class MultiTriangulation
  {
  public:
    /// Rest positions of all vertices (the input mesh's).
    std::vector<mesh::Point3> vertices;
    /// Every tetrahedron of every fragment, grouped by the node that inserts it.
    std::vector<mesh::Tet> tets;
    /// Per tet: the node that inserts it.
    std::vector<std::uint32_t> creator;
    /// Per tet: the node that removes it, mesh::invalid_index for input tetrahedra.
    std::vector<std::uint32_t> destroyer;
    /// Per node (plus one): the first tet it inserts.
    std::vector<std::uint32_t> fine_begin;
    /// Per node (plus one): where its coarse tets start in coarse_list.
    std::vector<std::uint32_t> coarse_begin;
    /// The coarse tets of all nodes, node after node.
    std::vector<std::uint32_t> coarse_list;
    /// Per node: the vertex it inserts (invalid_index for the root).
    std::vector<std::uint32_t> node_vertex;
    /// Per vertex: the node that inserts it (0 for the vertices of the root mesh).
    std::vector<std::uint32_t> vertex_node;
    /**
     * Per node: its error, the average volume of its coarse fragment (Section 4.1),
     * raised to the largest error of its descendants so that it never decreases from
     * a node to its parents. With ball, a bound for the node and all its descendants:
     * where the query allows this error over this ball, no descendant needs applying.
     */
    std::vector<double> error;
    /**
     * Per node: a ball (x, y, z, radius) that contains its fragments and the balls of
     * all its descendants, so that a query's smallest allowed error over the ball of a
     * node is never above that over the balls of its descendants.
     */
    std::vector<std::array<double, 4>> ball;
    /**
     * Fragments cuts have changed (mt/mt_cutter.h): per node, its fine (coarse)
     * tetrahedra once a cut has split one of them, in place of the range (list) above;
     * an empty vector means the fragment is unchanged. Both are empty (no entry per
     * node) until the first cut, and are not stored in MT files.
     */
    std::vector<std::vector<std::uint32_t>> cut_fine, cut_coarse;
    /// Per tet: 1 if a cut replaced it by its children (then it is in no fragment);
    /// empty until the first cut.
    std::vector<std::uint8_t> replaced;
    /**
     * For the vertices cuts created, the last cut_origin.size() ones: the tet whose
     * split created each. Empty until the first cut.
     */
    std::vector<std::uint32_t> cut_origin;
    /**
     * Per node, what cuts require of it (mt/mt_cutter.h): +1 it must be applied (it or
     * a descendant inserts a cut tetrahedron), -1 it must not be (it or an ancestor
     * removes one), 0 free. Only the levels of detail that were cut are split, so
     * every extraction keeps them where the cuts passed. Empty until the first cut.
     */
    std::vector<std::int8_t> cut_pin;
    /// The number of cuts applied to the MT: a level of detail re-tests every node
    /// after one (pins may have changed).
    unsigned int n_cut_updates = 0;
    /**
     * Per node: its own error, the average volume of its coarse fragment alone (0 for
     * the root). A tetrahedron satisfies a query when the node that removes it has an
     * own error within what the query allows over that node's own ball.
     */
    std::vector<double> own_error;
    /// Per node: a ball (x, y, z, radius) that contains its two fragments; the center
    /// is that of ball, so that own_ball lies inside ball.
    std::vector<std::array<double, 4>> own_ball;

    /// Number of nodes (the root included).
    unsigned int
    n_nodes() const
    {
      return static_cast<unsigned int>(node_vertex.size());
    }

    /// Number of tetrahedra over all fragments.
    unsigned int
    n_tets() const
    {
      return static_cast<unsigned int>(tets.size());
    }

    /// Number of vertices.
    unsigned int
    n_vertices() const
    {
      return static_cast<unsigned int>(vertices.size());
    }

    /// The id of the first vertex a cut created: ids from here on have a cut_origin.
    std::size_t
    first_cut_vertex() const
    {
      return vertices.size() - cut_origin.size();
    }

    /// Number of tetrahedra node @p j inserts.
    unsigned int
    n_fine(const unsigned int j) const
    {
      return cut_fine.empty() || cut_fine[j].empty()
               ? fine_begin[j + 1] - fine_begin[j]
               : static_cast<unsigned int>(cut_fine[j].size());
    }

    /// Number of tetrahedra node @p j removes.
    unsigned int
    n_coarse(const unsigned int j) const
    {
      return cut_coarse.empty() || cut_coarse[j].empty()
               ? coarse_begin[j + 1] - coarse_begin[j]
               : static_cast<unsigned int>(cut_coarse[j].size());
    }

    /// Calls @p f(t) for every tet t node @p j inserts (its fine fragment).
    template <typename Function>
    void
    for_each_fine(const unsigned int j, const Function &f) const
    {
      if (cut_fine.empty() || cut_fine[j].empty())
        for (std::uint32_t t = fine_begin[j]; t < fine_begin[j + 1]; ++t)
          f(t);
      else
        for (const std::uint32_t t : cut_fine[j])
          f(t);
    }

    /// Calls @p f(t) for every tet t node @p j removes (its coarse fragment).
    template <typename Function>
    void
    for_each_coarse(const unsigned int j, const Function &f) const
    {
      if (cut_coarse.empty() || cut_coarse[j].empty())
        for (std::uint32_t k = coarse_begin[j]; k < coarse_begin[j + 1]; ++k)
          f(coarse_list[k]);
      else
        for (const std::uint32_t t : cut_coarse[j])
          f(t);
    }

    /// What cuts require of node @p j: +1 applied, -1 not applied, 0 nothing.
    int
    pin(const unsigned int j) const
    {
      return cut_pin.empty() ? 0 : cut_pin[j];
    }

    /// Whether tet @p t belongs to the MT (a cut has not replaced it).
    bool
    is_live(const std::uint32_t t) const
    {
      return replaced.empty() || replaced[t] == 0;
    }

    /// Bytes held by the arrays.
    std::size_t
    memory_bytes() const;

    /// The rest positions of the four vertices of tet @p t, in its vertex order.
    std::array<mesh::Point3, 4>
    corners(unsigned int t) const;

    /**
     * Barycentric coordinates of point @p p in tet @p t (rest configuration); all are
     * >= 0 when p lies in the tet.
     */
    std::array<double, 4>
    barycentric(unsigned int t, const mesh::Point3 &p) const;

    /**
     * Checks the structure (index ranges, parents before children, every tet removed
     * by at most its destroyer, positive volumes); throws a lacerta::Error naming
     * @p source otherwise. Used after loading a file.
     */
    void
    check(const std::string &source) const;

    /// Writes or reads the state for a checkpoint (see lacerta::Archive).
    void
    serialize(Archive &archive);
  };
} // namespace lacerta::mt
