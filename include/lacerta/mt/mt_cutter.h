/**
 * @file
 * Cuts on the Multi-Triangulation (Section 5.1): the cutter's records replayed on the
 * MT's tetrahedra of the level of detail that was cut, and the nodes pinned so that
 * every later extraction keeps them.
 */
#pragma once

#include <lacerta/cut/cut_record.h>
#include <lacerta/mesh/vertex_stars.h>
#include <lacerta/mt/lod.h>
#include <lacerta/mt/multi_triangulation.h>

#include <cstdint>
#include <vector>

namespace lacerta
{
  class Archive;
}
namespace lacerta::mt
{
  /**
   * Updates a MultiTriangulation after a Cutter cut a level of detail extracted from it
   * (doc/mt-cutting.md).
   *
   * Every decision of a cut is the cutter's, made once: the MT replays its records
   * (cut::recorded_children()) on the MT tetrahedra of the cut level of detail, which
   * are the tetrahedra the records replaced, so the MT's version of that level is the
   * cutter's mesh, tetrahedron for tetrahedron and vertex for vertex. Children keep the
   * creator and destroyer of the tetrahedron they replace (the node's fragments list
   * them instead of the parent: MultiTriangulation::cut_fine, cut_coarse); new vertices
   * are appended to the MT in the cutter's order.
   *
   * The other levels are not cut again: a cut surface re-decided on another
   * tetrahedralisation makes other pieces than the blade did. The nodes are pinned
   * instead (MultiTriangulation::cut_pin): the creator of every replaced tetrahedron
   * and its ancestors must stay applied, its destroyer and that node's descendants
   * must stay undone, so every extraction (Lod::extract()) keeps the cut children
   * where the cut passed, at the resolution it was made at, and changes the level of
   * detail freely elsewhere. Every such extraction is conforming: the faces between
   * the cut children and the rest are faces of the cut mesh that no split touched.
   * The work is proportional to the tetrahedra cut and the nodes pinned, not to the MT.
   */
  class MtCutter
  {
  public:
    /// What an update did: the MT columns of the paper's Table 2.
    struct Statistics
    {
      /// Fragments split (SF: distinct nodes whose fine fragment had a tet split),
      /// MT tetrahedra cut (replaced) and created.
      unsigned int split_fragments = 0, cut_tets = 0, created_tets = 0;
      /// Vertices appended to the MT.
      unsigned int new_vertices = 0;
      /// Nodes newly pinned applied and undone.
      unsigned int pinned_applied = 0, pinned_undone = 0;
      /// Wall time of the update (MT-DAGUpd), seconds.
      double seconds = 0;
    };

    /// Prepares cutting @p mt (indexes its live tetrahedra by vertex).
    explicit MtCutter(MultiTriangulation &mt);

    /**
     * Replays @p records (made by a Cutter, in order, on the mesh of @p lod's level of
     * detail) on the MT. @p mt_vertex_of maps the cut mesh's vertex ids to MT ids: on
     * entry for the vertices the mesh had before the records, on return also for those
     * they created (appended to the MT). @p lod follows the splits (Lod::follow_cut()):
     * its active tetrahedra are then the cut mesh's. Throws if a record's tetrahedron
     * is not active in @p lod.
     */
    Statistics
    apply(const std::vector<cut::CutRecord> &records,
          std::vector<std::uint32_t>        &mt_vertex_of,
          Lod                               &lod);

    /// Writes or reads the state for a checkpoint (see lacerta::Archive).
    void
    serialize(Archive &archive);

  private:
    /// The live MT tet with vertices @p ids (any order), active in @p lod.
    std::uint32_t
    find_tet(const mesh::Tet &ids, const Lod &lod) const;

    /// Replaces @p parent by @p children in the fragment lists of its nodes.
    void
    replace_in_fragments(std::uint32_t                     parent,
                         const std::vector<std::uint32_t> &children);

    /// Pins the creator of @p parent (and its ancestors) applied and its destroyer
    /// (and its descendants) undone.
    void
    pin(std::uint32_t parent, Statistics &statistics);

    MultiTriangulation &mt;
    /// Per vertex: the tets containing it (replaced ones included; filtered on use).
    mesh::VertexStars vertex_tets;
  };
} // namespace lacerta::mt
