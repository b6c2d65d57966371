/**
 * @file
 * The children of the cells a sweep splits (doc/cutting.md, step 7): their points,
 * one particle per cut edge, their boundary ids, and one copy of every point on the
 * cut per side where the crack is open.
 */
#pragma once

#include <lacerta/cut/cut_record.h>
#include <lacerta/cut/cut_rules.h>
#include <lacerta/cut/cut_step_statistics.h>
#include <lacerta/cut/split_table.h>
#include <lacerta/mesh/tet_mesh.h>

#include <array>
#include <cstdint>
#include <vector>

namespace lacerta::physics
{
  class ParticleSystem;
}

namespace lacerta::cut
{
  class CrossingDecisions;

  /**
   * Makes the children of the cells a sweep splits, as the split table's results say,
   * on a mesh and its particle system: a new point on an edge becomes one vertex and
   * one particle for every cell around the edge (its state interpolated in its
   * parent, the same affine map at rest and deformed), children keep the boundary ids
   * of their parents' faces they lie on, and faces on the cut get cut_boundary_id.
   * Then every point on the cut that the sweep decides gets one copy per group of its
   * children connected through faces not on the cut (separate_star()), so that the
   * sides separate where the crack is open and stay joined at its tip.
   */
  class ChildBuilder
  {
  public:
    /// A builder that adds vertices to @p mesh and particles to @p system.
    ChildBuilder(mesh::TetMesh &mesh, physics::ParticleSystem &system);

    /// Reserves room for @p n_vertices vertices and @p n_edges edges.
    void
    reserve(std::size_t n_vertices, std::size_t n_edges);

    /**
     * The children of cells @p parents split as @p results say (split_tetrahedron()
     * of @p cuts, one per parent): children() and face_ids(). The copies of the
     * vertices @p separated and of the new points on the cut are decided; new points
     * and copies are on the cut of @p decisions' stroke. Counts go to @p statistics,
     * and, if @p record is given, what the Multi-Triangulation's update needs.
     */
    void
    build(const std::vector<unsigned int> &parents,
          const std::vector<TetCut>       &cuts,
          const std::vector<SplitResult>  &results,
          const std::vector<unsigned int> &separated,
          CrossingDecisions               &decisions,
          CutStepStatistics               &statistics,
          CutRecord                       *record);

    /// The children of the last build(), their vertices' copies chosen.
    const std::vector<mesh::Tet> &
    children() const
    {
      return made;
    }

    /// The boundary id of each face of each child (0 inside the body).
    const std::vector<std::array<unsigned int, 4>> &
    face_ids() const
    {
      return ids;
    }

  private:
    /// Grows the per-vertex and per-edge arrays to the mesh.
    void
    prepare();

    /// A particle at rest position @p rest in cell @p parent, its state interpolated.
    unsigned int
    new_particle(const Point &rest, unsigned int parent, CutStepStatistics &statistics);

    /// The children with their points (one particle per cut edge) and boundary ids,
    /// into `made`, `child_cut_faces` and `ids`.
    void
    make_children(const std::vector<unsigned int> &parents,
                  const std::vector<TetCut>       &cuts,
                  const std::vector<SplitResult>  &results,
                  CrossingDecisions               &decisions,
                  CutStepStatistics               &statistics,
                  CutRecord                       *record);

    /// Copies every point on the cut marked in `separate_mark` once per group of its
    /// children connected through faces not on the cut (separate_star()).
    void
    separate_points_on_cut(CrossingDecisions &decisions,
                           CutStepStatistics &statistics,
                           CutRecord         *record);

    mesh::TetMesh           &mesh;
    physics::ParticleSystem &system;

    /// Per edge: its new point's vertex in this build (valid where point_stamp is
    /// current).
    struct EdgePoint
    {
      unsigned int point_stamp = 0, point = 0;
    };
    std::vector<EdgePoint> edge_point;
    unsigned int           merge_stamp = 0;
    /// Per vertex: its copies are decided in this build (stamp).
    std::vector<unsigned int> separate_mark;
    unsigned int              separate_stamp = 0;

    std::vector<mesh::Tet>                   made;
    std::vector<std::uint8_t>                child_cut_faces;
    std::vector<std::array<unsigned int, 4>> ids;
    /// Per child, when recording: (split, child of the split).
    std::vector<std::array<unsigned int, 2>> child_origin;
    // Scratch of separate_points_on_cut().
    std::vector<std::array<unsigned int, 2>> incidences;
    std::vector<StarCell>                    star;
    std::vector<unsigned int>                star_group, copy_ids;
  };
} // namespace lacerta::cut
