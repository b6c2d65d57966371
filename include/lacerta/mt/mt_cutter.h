/**
 * @file
 * Cuts on the Multi-Triangulation (Section 5.1): every fragment the rest-configuration
 * cut surface crosses is split like the active level of detail was.
 */
#pragma once

#include <lacerta/cut/cut_record.h>
#include <lacerta/cut/geometry.h>
#include <lacerta/mesh/vertex_stars.h>
#include <lacerta/mt/lod.h>
#include <lacerta/mt/multi_triangulation.h>

#include <array>
#include <cstdint>
#include <vector>

namespace lacerta::mt
{
  /**
   * Updates a MultiTriangulation after the Cutter cut a level of detail extracted from
   * it (doc/mt-cutting.md).
   *
   * The cutter's records (cut::CutRecord) give the rest-configuration cut surface:
   * the cut faces of the children of every split it made, a triangle soup oriented
   * towards the +1 side. Every MT tetrahedron of any fragment near the soup, found
   * through a grid over the boxes of all tetrahedra at rest (built once, updated with
   * the children), is split by the cutter's table (cut::split_tetrahedron()) against
   * it. Every decision is made once per global edge or vertex: the crossing of edge
   * (a, b) with the soup and its snapping (the cutter's rule: a crossing within
   * ε·|edge| of a vertex puts the vertex on the cut), the side of every vertex, so a
   * tetrahedron shared by two fragments, and faces shared by neighbours at any level
   * of detail, split alike. Only complete cuts separate: where the soup ends inside a
   * tetrahedron (a crack front) the crack closes along its cut edges; the surface near
   * those tetrahedra is kept and cut again with later records whose surface meets it,
   * so that a crack continued from its front opens there too. Cut points are merged by
   * edge and side; a vertex on the cut gets one copy per group of children around it
   * connected through faces not on the cut (tetrahedra around it that the table leaves
   * whole keep it and connect the groups), over all levels at once, as the cutter does
   * within one mesh.
   *
   * Children keep the creator and destroyer of the tet they replace: the node's
   * fragments list them instead of the parent (MultiTriangulation::cut_fine,
   * cut_coarse). New vertices are appended to the MT with the tet whose split created
   * them (MultiTriangulation::cut_origin). The work is proportional to the
   * tetrahedra near the cut surface, not to the MT.
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
      /// Wall time of the update (MT-DAGUpd), seconds.
      double seconds = 0;
    };

    /**
     * Prepares cutting @p mt (indexes its tetrahedra at rest), splitting with snapping
     * fraction @p snap_fraction (the cutter's). @p boundary_error is the largest
     * distance between the boundaries of two levels, as a fraction of the bounding box
     * diagonal (the builder's `maximum_boundary_error`): the cut surface is extended
     * by twice that beyond the boundary of the level of detail that was cut, so that it
     * also crosses the levels whose boundary lies outside it.
     */
    explicit MtCutter(MultiTriangulation &mt,
                      double              snap_fraction  = cut::default_snap_fraction,
                      double              boundary_error = 0.01);

    /**
     * Splits the MT along the rest cut surface of @p records (made by a Cutter on a
     * level of detail of this MT, in order). If @p lod is given, its active tetrahedra
     * follow their splits (Lod::follow_cut()): it is then this MT's version of the cut
     * level of detail. If @p cut_mesh (the mesh the records were made on, after them)
     * is given, the surface is extended past its boundary, so that it also crosses the
     * levels whose boundary lies outside (the constructor's `boundary_error`).
     */
    Statistics
    apply(const std::vector<cut::CutRecord> &records,
          Lod                               *lod      = nullptr,
          const mesh::TetMesh               *cut_mesh = nullptr);

  private:
    /// Calls @p f(k) for the index k of every grid cell @p box meets.
    template <typename Function>
    void
    for_each_cell(const cut::Box &box, const Function &f) const
    {
      std::array<unsigned int, 3> lo, hi;
      for (unsigned int d = 0; d < 3; ++d)
      {
        const auto clamp = [&](const double x)
        {
          const double c = (x - origin[d]) / cell;
          return static_cast<unsigned int>(
            c < 0 ? 0.0 : (c > dims[d] - 1 ? double(dims[d] - 1) : c));
        };
        lo[d] = clamp(box.lower[d]);
        hi[d] = clamp(box.upper[d]);
      }
      for (unsigned int k = lo[2]; k <= hi[2]; ++k)
        for (unsigned int j = lo[1]; j <= hi[1]; ++j)
          for (unsigned int i = lo[0]; i <= hi[0]; ++i)
            f((std::size_t(k) * dims[1] + j) * dims[0] + i);
    }

    /// Box of tet @p t at rest.
    cut::Box
    tet_box(std::uint32_t t) const;

    /// Adds tet @p t to the grid and to the vertex incidence.
    void
    index_tet(std::uint32_t t);

    /// Appends the live tets whose box meets @p box (each once) to @p out.
    void
    query(const cut::Box &box, std::vector<std::uint32_t> &out);

    /// Replaces @p parent by @p children in the fragment lists of its nodes.
    void
    replace_in_fragments(std::uint32_t                     parent,
                         const std::vector<std::uint32_t> &children);

    MultiTriangulation &mt;
    double              snap_fraction;
    /// How far the cut surface is extended beyond the cut level's boundary (m).
    double rim_extension = 0;
    /// The grid over the tets' boxes at rest: origin, cell size, cells per axis.
    cut::Point                              origin{};
    double                                  cell = 1;
    std::array<unsigned int, 3>             dims{{1, 1, 1}};
    std::vector<std::vector<std::uint32_t>> cells;
    /// Per vertex: the tets containing it (replaced ones included; filtered on use).
    mesh::VertexStars vertex_tets;
    /// The triangles of earlier cut surfaces near the tetrahedra in which they ended
    /// (the crack closed there), with their normals towards +1: cut again together
    /// with later records whose surface meets them, so that a continuation (a tear
    /// continued after the update) completes the crack.
    std::vector<std::array<cut::Point, 3>> kept_surface;
    std::vector<cut::Point>                kept_normal;
    /// Per tet: the last query() that returned it.
    std::vector<std::uint32_t> seen;
    std::uint32_t              stamp = 0;
  };
} // namespace lacerta::mt
