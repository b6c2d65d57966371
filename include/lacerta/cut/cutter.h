/**
 * @file
 * The cutter: the scalpel's swept surface against the tissue, step by step (paper,
 * Sections 5.2 and 6), with the mesh and the particle system updated locally.
 */
#pragma once

#include <lacerta/cut/boundary_face_tree.h>
#include <lacerta/cut/cut_record.h>
#include <lacerta/cut/cut_rules.h>
#include <lacerta/cut/split_table.h>
#include <lacerta/cut/tool.h>
#include <lacerta/mesh/tet_mesh.h>
#include <lacerta/physics/assembly.h>

#include <deal.II/base/parameter_handler.h>

#include <array>
#include <chrono>
#include <cstdint>
#include <limits>
#include <optional>
#include <vector>

namespace dealii
{
  template <int dim, typename Number>
  class Function;
}
namespace lacerta::physics
{
  class ParticleSystem;
}

namespace lacerta::cut
{
  /// Boundary id of the faces a cut opens (the two sheets of the crack).
  inline constexpr unsigned int cut_boundary_id = 99;

  /**
   * What one blade motion did: the columns of the paper's Table 1 and a little more.
   */
  struct CutStepStatistics
  {
    /// Tetrahedra replaced (CuT) and tetrahedra created (CrT).
    unsigned int cut_tets = 0, created_tets = 0;
    /// Particles created (cut points, front points, copies of vertices on the cut).
    unsigned int new_particles = 0;
    /// Sub-steps of the swept surface, and those whose cut was postponed.
    unsigned int sweeps = 0, postponed = 0;
    /// Wall time of the local mesh and physics update, and of the force model's
    /// update for the springs the motion changed (ForceModel::springs_changed()), in
    /// seconds.
    double update_seconds = 0, reinit_seconds = 0;
    /**
     * Where the time went, in seconds. `search_seconds` (not part of update_seconds):
     * the boundary face tree's refit, the first contact and the propagation
     * (FindTetraToCut). The parts of update_seconds: `analysis_seconds` (sides, cut
     * edges, front points, the closure of the affected set, one TetCut per cell),
     * `split_seconds` (the split table and the checks that postpone a sweep),
     * `children_seconds` (the children's nodes, new particles, copies of the vertices
     * on the cut), `mesh_seconds` (TetMesh::replace_tets()) and `physics_seconds`
     * (masses, springs, the tree's new faces, the active set).
     */
    double search_seconds = 0, analysis_seconds = 0, split_seconds = 0,
           children_seconds = 0, mesh_seconds = 0, physics_seconds = 0;
    /// Whether the mesh changed (then the integrator must be re-initialised).
    bool changed = false;
    /**
     * Particles duplicated along the cut surface, as (original, copy), in the order
     * made (a copy can be copied again later). A copy starts with its original's
     * state and `free` flag; whoever holds particle lists (the scene's constraints)
     * extends them so that a fixed particle stays fixed and a handle keeps pulling.
     */
    std::vector<std::array<unsigned int, 2>> copied_particles;
  };

  /**
   * Cuts a tetrahedral mesh and its particle system with a moving blade.
   *
   * For every motion of the blade from its last position to @p next
   * (move_blade()): the motion is split into sweeps that advance at most
   * `Max advance` times the local edge length; for each sweep, the swept surface (the
   * two triangles {tail_t, head_t, tail_t+1} and {tail_t+1, head_t, head_t+1}) finds its
   * first contact through a BoundaryFaceTree, the cut tetrahedra by propagation from
   * the active ones through the cells around every intersected edge
   * (FindTetraToCut), and the split table (split_table.h) splits them. The cut is
   * computed on the deformed tissue and stored in the rest configuration: a cut point
   * at parameter t along an edge in the deformed mesh is the point at t along the same
   * edge at rest, i.e. the swept surface is mapped back through the piecewise-linear
   * deformation. Masses, springs and the new particles' states are updated locally.
   * See doc/cutting.md.
   */
  class Cutter
  {
  public:
    /// The cutter's parameters (`subsection Cut`).
    struct Parameters
    {
      double snap_fraction = default_snap_fraction;
      double max_advance   = 0.5;
    };

    /// Declares `subsection Cut`.
    static void
    declare_parameters(dealii::ParameterHandler &prm);

    /// Reads `subsection Cut`.
    static Parameters
    parse_parameters(dealii::ParameterHandler &prm);

    /**
     * Prepares cutting @p mesh (enables its local updates) and @p system, whose masses
     * and springs follow @p density and @p youngs_modulus; the blade starts at
     * @p initial. @p integral_of_density is ∫σ over the mesh, updated by every cut.
     */
    Cutter(mesh::TetMesh                     &mesh,
           physics::ParticleSystem           &system,
           const dealii::Function<3, double> &density,
           const dealii::Function<3, double> &youngs_modulus,
           double                            &integral_of_density,
           const Parameters                  &parameters,
           const Blade                       &initial);

    /**
     * The driver API: moves the blade from where it is to @p next (world coordinates,
     * the deformed configuration the system's positions describe) and cuts what it
     * sweeps. Call once per time step before integrating; when the result has
     * `changed`, re-initialise the integrator and recompute the critical time step.
     */
    CutStepStatistics
    move_blade(const Blade &next);

    /// Where the blade is.
    const Blade &
    blade() const
    {
      return current;
    }

    /**
     * Appends a CutRecord to @p records for every sweep that changes the mesh from now
     * on (nullptr stops recording): what the Multi-Triangulation update needs
     * (mt/mt_cutter.h).
     */
    void
    set_recorder(std::vector<CutRecord> *records)
    {
      recorder = records;
    }

    /**
     * Makes the vertices @p crack (on the cut surface of an earlier cutter on this
     * mesh, e.g. a tear whose particle system was rebuilt) vertices of this stroke's
     * crack: like the vertices this cutter put on the cut, they join the crack when
     * the front is past them, whatever the sweep's start, and are not a fresh patch
     * of vertices on the plane waiting to be swept as a whole. Call before the first
     * move_blade() of a stroke that continues that crack in its plane; the stroke's
     * end forgets them.
     */
    void
    adopt_crack(const std::vector<unsigned int> &crack);

    /// The active tetrahedra A_t (those the blade is in).
    const std::vector<unsigned int> &
    active_tets() const
    {
      return active;
    }

  private:
    /// The cut surface of one sweep (deformed configuration): the plane through the
    /// last crack front along the motion, bounded by the new front.
    struct SweepSurface
    {
      Point origin{}, normal{}, motion{}, start_dir{}, front_dir{}, end_tail{};

      /// Signed distance from the plane.
      double
      distance(const Point &x) const
      {
        return dot(normal, sub(x, origin));
      }

      /// Negative behind the new front (where the crack is).
      double
      behind(const Point &x) const
      {
        return dot(front_dir, sub(x, end_tail));
      }

      /// How far ahead of the sweep's start line (the last front), in the plane.
      double
      ahead_of_start(const Point &x) const
      {
        return dot(start_dir, sub(x, origin));
      }
    };

    /// Per-vertex scratch of the analysis, valid where `stamp` is the current one.
    /// What depends on the sweep only (distance, and on-plane and reached before the
    /// snapping and the patches) is kept for the sweep (`sweep_stamp`), so that the
    /// closure's later passes do not recompute it.
    struct VertexScratch
    {
      unsigned int stamp = 0, star_stamp = 0;
      /// Union-find parent (a vertex id) of the patch of on-plane vertices.
      unsigned int parent      = 0;
      unsigned int sweep_stamp = 0;
      double       d           = 0;
      bool         on_plane = false, reached = false, group_reached = false;
      bool         sweep_on_plane = false, sweep_reached = false;
      std::int8_t  side = 0;
    };

    /// Per-edge scratch: crossing, cut parameter, and the new particles on the edge
    /// (one per side -1, 0, +1) while children are made. Ordered for 32 bytes: two
    /// edges per cache line (the analysis reads it at random edge ids).
    struct EdgeScratch
    {
      double                      t     = 0;
      unsigned int                stamp = 0, point_stamp = 0;
      std::array<unsigned int, 3> point{};
      bool                        crossing = false, reached = false;
    };

    /// Per-face-slot (4 t + f) scratch: the front point (an index into `front_rest`)
    /// and its particle. Small (16 bytes, a cell's four faces in one cache line): the
    /// analysis visits every face of the affected cells and few have a front point.
    struct FaceScratch
    {
      /// `front` of a face without a front point.
      static constexpr unsigned int no_front = std::numeric_limits<unsigned int>::max();

      unsigned int stamp = 0, point_stamp = 0, point = 0, front = no_front;

      /// Whether the face has a front point in this pass of the analysis.
      bool
      has_front() const
      {
        return front != no_front;
      }
    };

    /// One sweep from the last applied crack front to @p end; at a corner of the
    /// path, first a sweep that brings the front to the corner.
    void
    sweep(const Blade &end, CutStepStatistics &statistics);

    /// One sweep from the last applied crack front to @p end, a straight motion.
    void
    sweep_once(const Blade &end, CutStepStatistics &statistics);

    /// FindTetraToCut: fills `candidates` (C) and `next_active` (A_t+1).
    void
    find_tets_to_cut(const std::array<std::array<Point, 3>, 2> &swept, const Blade &end);

    /// Whether tetrahedron @p t meets the swept triangles (deformed configuration).
    bool
    tet_meets(unsigned int t, const std::array<std::array<Point, 3>, 2> &swept) const;

    /// Whether the segment (blade) meets tetrahedron @p t.
    bool
    blade_in_tet(unsigned int t, const Blade &b) const;

    /// Current position of particle @p v.
    Point
    position(unsigned int v) const;

    /// Ends the stroke: vertices on the cut lose that status.
    void
    end_stroke();

    /// Grows the scratch arrays to the mesh (new entries are invalid).
    void
    prepare_scratch();

    /// The scratch of vertex @p v, computed for @p surface if not yet in this pass.
    VertexScratch &
    vertex_data(unsigned int v, const SweepSurface &surface);

    /// Sides, cut edges and front points on `affected`, closed under what must be
    /// split alike.
    void
    analyse(const SweepSurface &surface);

    /// The front point of face @p f of tetrahedron @p t, into @p fs.
    void
    compute_front_point(unsigned int        t,
                        unsigned int        f,
                        const SweepSurface &surface,
                        FaceScratch        &fs);

    /// Adds tetrahedron @p t to the affected set unless it is there already.
    void
    join_affected(unsigned int t);

    /// Whether tetrahedron @p t has a cut edge or a front face in the analysis.
    bool
    tet_is_cut(unsigned int t) const;

    /// Whether a child of the split is flat at rest.
    bool
    has_flat_child(const TetCut &cut, const SplitResult &result) const;

    /// Replaces `removed` by the children of `results`, copies the vertices on the
    /// cut, updates masses, springs and the active set.
    void
    apply(const Blade &end, CutStepStatistics &statistics);

    /// Vertex @p v lies on the cut of the current stroke.
    void
    mark_on_surface(unsigned int v);

    /// Adds the time since the last lap to @p phase (per-phase statistics).
    void
    lap(double &phase);

    mesh::TetMesh                     &mesh;
    physics::ParticleSystem           &system;
    const dealii::Function<3, double> &density;
    const dealii::Function<3, double> &youngs_modulus;
    double                            &integral_of_density;
    /// The mass contributions if the density is constant (physics::constant_value()).
    std::optional<physics::ConstantDensityMass> constant_density_mass;
    /// Young's modulus if it is constant (physics::constant_value()).
    std::optional<double> constant_youngs_modulus;
    Parameters            parameters;
    Blade                 current;
    /// The crack front as last applied: the start of the next swept surface.
    Blade front;
    /// Where the blade was at the end of the last sweep tried: a corner of the path
    /// when the next motion turns away from the direction since the front.
    Blade last_end;
    /// Whether the sweep being made brings the front to a corner, and whether the
    /// front has not advanced since it reached one: children of these sweeps may be
    /// thin (the crack bends inside a cell; see has_flat_child()).
    bool catching_up = false, after_corner = false;
    /// The corner the front is being brought to, while that has not succeeded yet.
    Blade corner;
    bool  corner_pending = false;
    /// Typical edge length at rest (median), for the sub-division when nothing is active.
    double typical_edge = 0;
    /// The current stroke (from entering the tissue to leaving it), from 1, and
    /// whether it has cut anything yet.
    unsigned int stroke         = 1;
    bool         stroke_has_cut = false;
    /// How far behind its start line the current sweep's plane cuts.
    double start_reach = 0;

    BoundaryFaceTree          tree;
    std::vector<unsigned int> active, next_active, candidates, queue;
    std::vector<unsigned int> tet_stamp, edge_stamp;
    unsigned int              stamp = 0;
    /// Vertices on the cut surface of the current stroke (progressive cuts).
    std::vector<std::uint8_t> on_surface;
    std::vector<unsigned int> on_surface_list;
    /// Where each vertex of the stroke's crack was (world) when it joined the crack;
    /// for a vertex a sweep of the stroke swept on the plane but that is not on the
    /// crack, where it was first swept. Later sweeps judge the vertex there.
    std::vector<Point>                  joined_at;
    std::vector<BoundaryFaceTree::Face> hits;
    /// Stroke in which a vertex on the plane was swept by the blade (its patch opens
    /// when all of it is swept).
    std::vector<unsigned int> swept;
    /// Stroke in which a vertex of the crack lay on the plane ahead of the front (a
    /// later sweep that reaches it re-splits its star).
    std::vector<unsigned int> crossing_pending;
    /// Stroke in which a tetrahedron was made by a partial split (not split partially
    /// again while the front is inside it).
    std::vector<unsigned int> partial_child;
    /// The edges (their ends) that the last applied sweep's plane crossed ahead of its
    /// front, where the crack tip waits, and their ids in the current sweep (sorted).
    std::vector<std::array<unsigned int, 2>> front_edges;
    std::vector<unsigned int>                front_edge_ids;

    // Scratch, kept between sweeps so that no sweep allocates or clears O(mesh).
    std::vector<VertexScratch> vertex_scratch;
    std::vector<EdgeScratch>   edge_scratch;
    std::vector<FaceScratch>   face_scratch;
    /// The front points (rest configuration) of the analysis pass, by FaceScratch::front.
    std::vector<Point>        front_rest;
    std::vector<unsigned int> tet_mark;
    unsigned int analysis_stamp = 0, star_stamp = 0, affected_stamp = 0, merge_stamp = 0;
    std::vector<unsigned int> affected, verts, edge_list, group, group_extra, missing,
      around, removed, added_ids, touched_vertices, star_group, copy_ids;
    std::vector<TetCut>                      cuts;
    std::vector<SplitResult>                 results;
    std::vector<mesh::Tet>                   children;
    std::vector<std::uint8_t>                child_cut_faces;
    std::vector<bool>                        child_partial;
    std::vector<std::array<unsigned int, 4>> face_ids;
    std::vector<std::array<unsigned int, 2>> incidences;
    std::vector<StarCell>                    star;
    mesh::TetMesh::EdgeUpdate                edge_update;
    /// The end of the last lap().
    std::chrono::steady_clock::time_point lap_start;
    /// The springs the sweeps of the current blade motion added, moved or restiffened,
    /// passed to ParticleSystem::springs_changed() at its end.
    std::vector<unsigned int> changed_springs;
    /// Where sweeps are recorded (set_recorder()), or nullptr.
    std::vector<CutRecord> *recorder = nullptr;
    /// Per child of the sweep being applied, when recording: (split, child of the split).
    std::vector<std::array<unsigned int, 2>> child_origin;
  };
} // namespace lacerta::cut
