/**
 * @file
 * What one applied sweep of the cutter did, in the rest configuration: enough to split
 * another tetrahedralisation of the same object (the Multi-Triangulation, Section 5.1)
 * identically where it coincides with the cut mesh.
 */
#pragma once

#include <lacerta/cut/split_table.h>
#include <lacerta/mesh/tet_mesh.h>

#include <array>
#include <cstdint>
#include <vector>

namespace lacerta
{
  class Archive;
}
namespace lacerta::cut
{
  /**
   * The record of one sweep the cutter applied (Cutter::set_recorder()), with the cut
   * mesh's vertex ids of that moment. The split of every replaced tetrahedron is the
   * split table applied to its TetCut, so the rest-configuration cut surface (the cut
   * faces of the children) and the crack front (the front points) follow from `cuts`;
   * the cut points on edges are exact and keyed by the edge's two vertex ids. What the
   * table leaves to the cutter is recorded explicitly: the ids of the particles it
   * created, with their keys, and which copy of a point on the cut (a vertex or a cut
   * point) each child uses.
   */
  struct CutRecord
  {
    /// A particle the sweep created.
    struct NewPoint
    {
      /// Its vertex id in the cut mesh.
      unsigned int id = 0;
      /// Cut point on an edge (one per edge: where the crack opens at it, its copies
      /// are recorded like those of a vertex on the cut), front point on a face,
      /// interior point, or a copy of a point on the cut (NodeKind::vertex).
      NodeKind kind = NodeKind::vertex;
      /**
       * The key's vertex ids, sorted: the edge's two, the face's three, the four of the
       * split tetrahedron for an interior point, the copied vertex for a copy; unused
       * entries are 0.
       */
      std::array<unsigned int, 4> ids{};
      /// Its rest position.
      Point position{};
    };

    /**
     * The vertex a child uses at a node that is a vertex on the cut: the vertex itself
     * or one of its copies, as the cutter decided from the connectivity of the
     * children around it.
     */
    struct VertexChoice
    {
      /// The split (index into `cuts`), the child of its split, the node of the child.
      unsigned int cut   = 0;
      std::uint8_t child = 0, node = 0;
      /// The vertex the child uses there.
      unsigned int used = 0;
    };

    /// The cut of every tetrahedron the sweep replaced (vertex ids of the cut mesh).
    std::vector<TetCut> cuts;
    /// The snap fraction the cutter split them with (split_tetrahedron()).
    double snap_fraction = default_snap_fraction;
    /// The particles created, in creation order (increasing ids).
    std::vector<NewPoint> new_points;
    /// The vertex every child uses at each of its nodes on the cut.
    std::vector<VertexChoice> vertex_choices;

    /// Writes or reads the record for a checkpoint (see lacerta::Archive).
    void
    serialize(Archive &archive);
  };

  /**
   * The key a record gives the point that node @p node of a child of split @p cut
   * stands for (CutRecord::NewPoint::ids): the edge's two or the face's three vertex
   * ids, or the split tetrahedron's four for an interior point, sorted, unused
   * entries 0. The cutter records its new points under it and recorded_children()
   * finds them by it.
   */
  std::array<unsigned int, 4>
  record_key(const TetCut &cut, const NodeRef &node);

  /**
   * The children the cutter made of every tetrahedron @p record replaced, in the cut
   * mesh's vertex ids: entry k lists those of `record.cuts[k]`, in the table's order.
   * They follow from the record alone (the table's split of each TetCut, with the
   * recorded particle of every new point and the recorded copy of every point on the
   * cut), so replaying the records of a stroke in order on the mesh it started from
   * rebuilds the cut mesh exactly. Throws if a new point has no recorded particle.
   */
  std::vector<std::vector<mesh::Tet>>
  recorded_children(const CutRecord &record);
} // namespace lacerta::cut
