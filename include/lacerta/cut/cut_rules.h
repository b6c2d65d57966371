/**
 * @file
 * The decisions a mesh cutter takes around the split table (doc/split-table.md,
 * "Partial and progressive cutting"), one implementation shared by the Cutter and the
 * tests' reference cutter: where the crack front crosses a face, how the children
 * around a vertex on the cut fall into separate copies, and where a child's nodes are.
 * Plain C++17, no deal.II.
 */
#pragma once

#include <lacerta/cut/split_table.h>

#include <array>
#include <cstdint>
#include <functional>
#include <vector>

namespace lacerta::cut
{
  /**
   * A corner of the section of a face by the cut plane: a vertex on the cut, or the
   * crossing of an edge; at rest and in the configuration the front is measured in,
   * and whether the crack has reached it.
   */
  struct SectionCorner
  {
    Point rest{};
    Point now{};
    bool  reached = false;
  };

  /**
   * The crack front's point on one face from the face's section corners (the first
   * @p n_vertex_corners of which are vertices on the cut): it exists when the section is
   * a segment between a reached and an unreached corner that is not an edge lying in
   * the cut (two vertex corners); it lies where @p behind (negative behind the front)
   * changes sign, clamped at least @p snap_fraction from both corners
   * (clamp_front_parameter()). Returns whether there is one, and its positions at rest
   * and now.
   */
  bool
  front_point_on_face(const SectionCorner                        *corners,
                      unsigned int                                n_corners,
                      unsigned int                                n_vertex_corners,
                      const std::function<double(const Point &)> &behind,
                      double                                      snap_fraction,
                      Point                                      &rest,
                      Point                                      &now);

  /**
   * One cell of the star of a vertex after splitting: its four nodes and which of its
   * faces lie on the cut (bit j: the face opposite node j, as Child::cut_faces).
   */
  struct StarCell
  {
    std::array<std::uint64_t, 4> nodes{};
    std::uint8_t                 cut_faces = 0;
  };

  /**
   * Groups the cells of the star of vertex @p v that are connected through faces
   * containing @p v and not on the cut: each group gets its own copy of @p v, so the
   * sides separate where the crack is open and stay joined at the crack tip. Writes
   * the group of every cell to @p group (the first cell's group is 0) and returns the
   * number of groups.
   */
  unsigned int
  separate_star(std::uint64_t                v,
                const std::vector<StarCell> &star,
                std::vector<unsigned int>   &group);

  /**
   * Rest positions of the four nodes of @p child, a child of the split @p result of
   * @p cut.
   */
  std::array<Point, 4>
  child_node_points(const TetCut &cut, const SplitResult &result, const Child &child);
} // namespace lacerta::cut
