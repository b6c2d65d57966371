/**
 * @file
 * FindTetraToCut (paper, Section 5.1): the cells one sweep of the blade meets, found
 * from the cells the blade is in and from first contact with the boundary, never by a
 * search over the mesh (doc/cutting.md, steps 3 and 4).
 */
#pragma once

#include <lacerta/cut/boundary_face_tree.h>
#include <lacerta/cut/crossing_decisions.h>
#include <lacerta/cut/tool.h>

#include <array>
#include <vector>

namespace lacerta
{
  class Archive;
}
namespace lacerta::physics
{
  class ParticleSystem;
}

namespace lacerta::cut
{
  /**
   * The cells a sweep meets (C_t,t+1) and the cells the blade is in (A_t), on a mesh
   * whose particles' positions are those of a particle system. First contact goes
   * through a BoundaryFaceTree over the boundary faces; from there and from the active
   * cells a queue visits the cells around every edge the sweep crosses. The tree and
   * the active cells follow the local mesh updates (follow_replacement()).
   */
  class SweepSearch
  {
  public:
    /// A search on @p mesh, deformed as the positions of @p system say.
    SweepSearch(const mesh::TetMesh &mesh, const physics::ParticleSystem &system);

    /// Reserves room for @p n_tets cells and @p n_edges edges.
    void
    reserve(std::size_t n_tets, std::size_t n_edges);

    /// Refits the boundary face tree to the current positions (only where vertices
    /// moved farther than its boxes' margin).
    void
    refit();

    /**
     * FindTetraToCut for sweep @p swept, which leaves the blade at @p end: cells() are
     * then the cells the swept triangles meet, and active() the cells the blade is in
     * at @p end.
     */
    void
    find(const SweptTriangles &swept, const Blade &end);

    /// The cells the last sweep met (C_t,t+1), in the order the search reached them.
    const std::vector<unsigned int> &
    cells() const
    {
      return met;
    }

    /// The cells the blade is in (A_t).
    const std::vector<unsigned int> &
    active() const
    {
      return active_cells;
    }

    /**
     * After the mesh replaced the cells @p removed by @p added (TetMesh::replace_tets()):
     * the new boundary faces join the tree, and the active cells are those that stay
     * and the new ones blade @p end is in.
     */
    void
    follow_replacement(const std::vector<unsigned int> &removed,
                       const std::vector<unsigned int> &added,
                       const Blade                     &end);

    /// Whether cell @p t meets the swept triangles @p swept (deformed configuration).
    bool
    tet_meets(unsigned int t, const SweptTriangles &swept) const;

    /// Whether blade @p b (a segment) meets cell @p t (deformed configuration).
    bool
    blade_in_tet(unsigned int t, const Blade &b) const;

    /// Writes or reads the tree and the active cells for a checkpoint (see
    /// lacerta::Archive).
    void
    serialize(Archive &archive);

  private:
    /// Current position of particle @p v.
    Point
    position(unsigned int v) const;

    /// Current positions of the vertices of cell @p t.
    std::array<Point, 4>
    corners(unsigned int t) const;

    const mesh::TetMesh           &mesh;
    const physics::ParticleSystem &system;
    BoundaryFaceTree               tree;
    std::vector<unsigned int>      active_cells, next_active, met;
    // Scratch of find(), kept between sweeps so that no sweep clears O(mesh).
    std::vector<unsigned int>           queue, around, sorted_removed;
    std::vector<BoundaryFaceTree::Face> hits;
    /// Per cell and per edge: the sweep that reached it last.
    std::vector<unsigned int> tet_stamp, edge_stamp;
    unsigned int              stamp = 0;
  };
} // namespace lacerta::cut
