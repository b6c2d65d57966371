/**
 * @file
 * The cells one sweep changes (doc/cutting.md, step 6): those its decisions cut
 * through, the closure around the crossings they apply, and the stars of the points
 * on the cut whose copies are decided.
 */
#pragma once

#include <lacerta/cut/split_table.h>
#include <lacerta/mesh/tet_mesh.h>

#include <cstdint>
#include <vector>

namespace lacerta::cut
{
  class CrossingDecisions;

  /**
   * Selects, from the stroke's decisions after a sweep, the cells the sweep changes
   * and how: a cell cut through (CrossingDecisions::decide_cell()) applies its
   * crossings, every cell around an applied crossing is split with it (so that the
   * mesh stays conforming: refined through the cut point if the surface does not cut
   * it through yet), and the points on the cut in a cell cut through, or on a face
   * that came into the cut in this sweep, get their copies decided over their whole
   * stars. All of it is a closure from the sweep's new decisions: local, nothing
   * postponed.
   */
  class CellSelection
  {
  public:
    /// A selection on @p mesh.
    explicit CellSelection(const mesh::TetMesh &mesh);

    /// Reserves room for @p n_tets cells and @p n_vertices vertices.
    void
    reserve(std::size_t n_tets, std::size_t n_vertices);

    /**
     * Selects the cells the last CrossingDecisions::record_sweep() of @p decisions
     * changes, and marks the crossings they apply (CrossingDecisions::apply_crossing()).
     */
    void
    select(CrossingDecisions &decisions);

    /// The cells that change, in the order of cuts().
    const std::vector<unsigned int> &
    removed() const
    {
      return removed_cells;
    }

    /// How each of removed() is split (split_tetrahedron()): cut through, refined
    /// through applied cut points, or re-emitted whole with its faces on the cut
    /// flagged.
    const std::vector<TetCut> &
    cuts() const
    {
      return cell_cuts;
    }

    /// The points on the cut whose copies the sweep decides.
    const std::vector<unsigned int> &
    separated() const
    {
      return separated_vertices;
    }

  private:
    /// Grows the per-cell and per-vertex marks to the mesh.
    void
    prepare();

    /// The closure: the cells the sweep changes, into `affected`.
    void
    select_cells(CrossingDecisions &decisions);

    /// One TetCut per cell of `affected` that changes.
    void
    make_cuts(const CrossingDecisions &decisions);

    const mesh::TetMesh      &mesh;
    std::vector<unsigned int> removed_cells, separated_vertices;
    std::vector<TetCut>       cell_cuts;
    // Scratch, kept between sweeps so that no sweep allocates or clears O(mesh).
    /// Per cell: in `affected` (stamp), and in the star of a vertex whose copies are
    /// decided. Per vertex: its copies are decided (stamp); it came onto the cut in
    /// this sweep (stamp).
    std::vector<unsigned int> tet_mark, separate_mark, fresh_mark;
    std::vector<std::uint8_t> in_star;
    unsigned int              affected_stamp = 0;
    std::vector<unsigned int> affected, around;
  };
} // namespace lacerta::cut
