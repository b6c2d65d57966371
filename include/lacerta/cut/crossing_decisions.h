/**
 * @file
 * The scalpel's decisions of a stroke, each made once and recorded in the rest
 * frame: which mesh edges the swept surface crosses and where, on which side of the
 * surface a vertex lies, and which vertices lie on the cut (doc/cutting.md, steps 5
 * and 6).
 */
#pragma once

#include <lacerta/cut/split_table.h>

#include <array>
#include <cstdint>
#include <unordered_map>
#include <vector>

namespace lacerta
{
  class Archive;
}
namespace lacerta::mesh
{
  class TetMesh;
}
namespace lacerta::physics
{
  class ParticleSystem;
}

namespace lacerta::cut
{
  /// The two triangles one sweep of the blade covers, {tail_t, head_t, tail_t+1} and
  /// {tail_t+1, head_t, head_t+1} (deformed configuration).
  using SweptTriangles = std::array<std::array<Point, 3>, 2>;

  /**
   * What the swept surface of the current stroke decided about the mesh, and the
   * rules that decide it. Each decision is made once, with exact predicates, when a
   * sweep first meets it, and kept in rest terms (a parameter along an edge, a side):
   * the tissue moving afterwards never changes it. The decisions last until the
   * stroke ends (end_stroke()); the crossings a sweep applies go when their edges are
   * split (forget_applied()).
   *
   * The rules are public so that each can be tested on its own.
   */
  class CrossingDecisions
  {
  public:
    /**
     * A crossing of a mesh edge by the stroke's swept surface: where (the parameter
     * along the edge from its end with the smaller id, the same at rest as deformed)
     * and which way (the side of the surface that end lies on, +1 or -1; 0: no
     * crossing).
     */
    struct Crossing
    {
      double      t    = 0;
      std::int8_t side = 0;
      /// Whether the sweep being applied cuts the edge.
      bool applied = false;
    };

    /**
     * What the crossings decided so far make of one cell: the crossed local edges and
     * their parameters, and whether they cut it through (its vertices off the cut
     * fall into two sides, each crossed edge joining the two), with the sides.
     */
    struct CellDecision
    {
      std::uint8_t               crossed = 0;
      std::array<double, 6>      t{};
      std::array<std::int8_t, 4> side{};
      bool                       complete = false;
    };

    /// The key of the edge between vertices @p a and @p b.
    static std::uint64_t
    edge_key(const unsigned int a, const unsigned int b)
    {
      return (std::uint64_t(std::min(a, b)) << 32) | std::max(a, b);
    }

    /// End @p i (0: the smaller id) of the edge with key @p key.
    static unsigned int
    edge_end(const std::uint64_t key, const unsigned int i)
    {
      return static_cast<unsigned int>(i == 0 ? key >> 32 : key & 0xFFFFFFFFu);
    }

    /// Decisions on @p mesh, whose particles' positions are those of @p system, with
    /// the snapping distance @p snap_fraction (`Cut/Snap fraction`) of the cells' size.
    CrossingDecisions(const mesh::TetMesh           &mesh,
                      const physics::ParticleSystem &system,
                      double                         snap_fraction);

    /// Reserves room for @p n_vertices vertices and @p n_edges edges.
    void
    reserve(std::size_t n_vertices, std::size_t n_edges);

    /// Grows the per-vertex and per-edge arrays to the mesh (new entries undecided).
    void
    prepare();

    /**
     * Decides, once, the crossings of the edges of @p cells by the sweep @p swept,
     * and the vertices the surface passes through (snapping); new_crossings() and
     * new_on_cut() list what this sweep decided.
     */
    void
    record_sweep(const std::vector<unsigned int> &cells, const SweptTriangles &swept);

    /// The crossings the last record_sweep() decided or forgot (their cells change).
    const std::vector<std::uint64_t> &
    new_crossings() const
    {
      return fresh_crossings;
    }

    /// The vertices the last record_sweep() put on the cut, and those of a crack
    /// adopted since the sweep before (adopt()).
    const std::vector<unsigned int> &
    new_on_cut() const
    {
      return fresh_on_cut;
    }

    /// Whether vertex @p v lies on the cut of the current stroke.
    bool
    on_cut(const unsigned int v) const
    {
      return v < on_surface.size() && on_surface[v] != 0;
    }

    /// Vertex @p v lies on the cut of the current stroke from now on.
    void
    mark_on_cut(unsigned int v);

    /// What the decided crossings make of cell @p t.
    CellDecision
    decide_cell(unsigned int t) const;

    /// Marks the crossing of the edge with key @p key (which must be decided) as
    /// applied by the current sweep; true the first time.
    bool
    apply_crossing(std::uint64_t key);

    /// Whether the crossing of the edge with key @p key is applied by this sweep.
    bool
    is_applied(std::uint64_t key) const;

    /// Removes the crossings the sweep applied (their edges are split).
    void
    forget_applied();

    /**
     * The TetCut that leaves cell @p t whole: its vertices on the cut at 0, the others
     * on one side (the side the stroke found them on, or for those it has not judged,
     * their side of the current sweep's plane), so that the table flags its faces
     * lying in the cut, facing the surface's orientation.
     */
    TetCut
    whole_cell(unsigned int t) const;

    /**
     * Makes the vertices @p crack vertices on the cut of this stroke whose copies the
     * next sweep decides (Cutter::adopt_crack()).
     */
    void
    adopt(const std::vector<unsigned int> &crack);

    /// Ends the stroke: vertices on the cut lose that status, the crossings not
    /// applied and the vertices' sides are forgotten.
    void
    end_stroke();

    /// Writes or reads the decisions for a checkpoint (see lacerta::Archive).
    void
    serialize(Archive &archive);

    /**
     * How the edge from @p a to @p b (a < b) crosses the swept triangles, whose unit
     * normal is @p normal, exactly: the ends' sides are those kept for this part of the
     * surface, or where the ends are now (a point on the plane counts as on the
     * positive side). Also the ends' distances from the surface's plane, in edge
     * lengths, into @p distance (for the snapping).
     */
    Crossing
    edge_crossing(unsigned int           a,
                  unsigned int           b,
                  const SweptTriangles  &swept,
                  const Point           &normal,
                  std::array<double, 2> &distance) const;

    /// The size of the cells around the edge from @p a to @p b (their longest edge at
    /// rest): the snapping distance is a fraction of it.
    double
    cell_size_around(unsigned int a, unsigned int b) const;

    /**
     * Whether vertex @p v may be put on the cut: not if a crossing of one of its edges
     * was decided (it lies off the cut), nor if a cell around it would then have all
     * four vertices on the cut (a cell in the crack, cut off from both sides).
     */
    bool
    may_snap(unsigned int v) const;

    /**
     * Whether the current part of the swept surface reaches within @p distance of
     * vertex @p v (deformed): the vertex lies ahead of the start of the current sweep
     * @p swept, or within @p distance of its triangles or of the part's earlier
     * sweeps. A part that starts at a corner does not reach behind the corner.
     */
    bool
    part_reaches(unsigned int v, double distance, const SweptTriangles &swept) const;

    /// The side vertex @p v was given for the part of the surface with unit normal
    /// @p normal in this stroke, or 0.
    std::int8_t
    kept_side(unsigned int v, const Point &normal) const;

  private:
    /// Vertex @p v lies on side @p side of the part of the surface with unit normal
    /// @p normal, unless a side was decided for that part already.
    void
    keep_side(unsigned int v, std::int8_t side, const Point &normal);

    /// Vertex @p v lies on the cut from now on (decided in this sweep).
    void
    put_on_cut(unsigned int v);

    /// Removes the crossing at @p it; returns the next one.
    std::unordered_map<std::uint64_t, Crossing>::iterator
    forget_crossing(std::unordered_map<std::uint64_t, Crossing>::iterator it);

    /// Starts a new part for a sweep with unit normal @p normal if the blade turned by
    /// more than 45 degrees since its last sweep (or the stroke begins).
    void
    follow_part(const Point &normal);

    /// Keeps the current sweep's @p swept triangles in `part`.
    void
    keep_part_sweep(const SweptTriangles &swept);

    /// Current position of particle @p v.
    Point
    position(unsigned int v) const;

    const mesh::TetMesh           &mesh;
    const physics::ParticleSystem &system;
    double                         snap_fraction;

    /// The current stroke (from entering the tissue to leaving it), from 1.
    unsigned int stroke = 1;
    /// The crossings decided in the current stroke and not applied yet, by edge key.
    std::unordered_map<std::uint64_t, Crossing> crossings;
    /// Per vertex, the number of its edges in `crossings`.
    std::vector<unsigned int> crossings_at;
    /// The crossings the current sweep applies.
    std::vector<std::uint64_t> applied_crossings;
    /// Vertices on the cut surface of the current stroke.
    std::vector<std::uint8_t> on_surface;
    std::vector<unsigned int> on_surface_list;
    /// What the last sweep decided, and the vertices of an adopted crack waiting for
    /// the next sweep.
    std::vector<std::uint64_t> fresh_crossings;
    std::vector<unsigned int>  fresh_on_cut, adopted;

    /**
     * The side of the swept surface a vertex next to it was found on, once, in the
     * stroke `stroke`, for the part of the surface with unit normal `normal`.
     */
    struct SideRecord
    {
      std::int8_t  side   = 0;
      unsigned int stroke = 0;
      Point        normal{};
    };
    std::vector<SideRecord> side_records;
    /// A triangle the current sweep swept (deformed).
    std::array<Point, 3> sweep_triangle{};

    /**
     * The part of the swept surface the current sweep belongs to: a new part starts
     * where the blade turns by more than 45 degrees from its last sweep (a corner of
     * the path). `normal` is the unit normal of its last sweep (zero between strokes),
     * `triangles` the triangles of its sweeps before the current one (deformed, at most
     * `kept_part_sweeps` sweeps).
     */
    struct SurfacePart
    {
      Point                             normal{};
      std::vector<std::array<Point, 3>> triangles;
    };
    SurfacePart part;
    /// How many earlier sweeps of the current part `part` keeps.
    static constexpr unsigned int kept_part_sweeps = 8;

    /// Per edge: the sweep that tested it last (so that a sweep tests each edge once).
    std::vector<unsigned int> edge_seen;
    unsigned int              sweep_stamp = 0;
  };
} // namespace lacerta::cut
