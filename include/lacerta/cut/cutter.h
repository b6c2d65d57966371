/**
 * @file
 * The cutter: the scalpel's swept surface against the tissue, step by step (paper,
 * Sections 5.2 and 6), with the mesh and the particle system updated locally.
 */
#pragma once

#include <lacerta/cut/cell_selection.h>
#include <lacerta/cut/child_builder.h>
#include <lacerta/cut/crossing_decisions.h>
#include <lacerta/cut/cut_record.h>
#include <lacerta/cut/cut_rules.h>
#include <lacerta/cut/cut_step_statistics.h>
#include <lacerta/cut/split_table.h>
#include <lacerta/cut/sweep_search.h>
#include <lacerta/cut/tool.h>
#include <lacerta/mesh/tet_mesh.h>
#include <lacerta/physics/topology_update.h>

#include <deal.II/base/parameter_handler.h>

#include <array>
#include <chrono>
#include <cstdint>
#include <limits>
#include <optional>
#include <unordered_map>
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

namespace lacerta
{
  class Archive;
}
namespace lacerta::cut
{
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

    /**
     * The most sweeps one blade motion may take. A motion that needs more (its length
     * over `Maximum advance` times the element size around the blade) is a tool that
     * jumps across the scene or tissue that has blown up around the blade: move_blade()
     * stops with an error instead of sweeping for hours.
     */
    static constexpr double max_sweeps_per_motion = 1e5;

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
      return search.active();
    }

    /// Writes or reads the state for a checkpoint (see lacerta::Archive).
    void
    serialize(Archive &archive);

  private:
    /// One sweep of the blade from @p from to @p to: crossings, cells, split, update.
    void
    sweep(const Blade &from, const Blade &to, CutStepStatistics &statistics);
    /// Current position of particle @p v.
    Point
    position(unsigned int v) const;
    /// Replaces the selected cells by their children (ChildBuilder), then updates the
    /// mesh, masses, springs and the search's active cells (TopologyUpdate, SweepSearch).
    void
    apply(const Blade &end, CutStepStatistics &statistics);

    /// After the mesh update: masses that rounding left a hair below zero clamped.
    void
    clamp_rounded_masses();


    /// Adds the time since the last lap to @p phase (per-phase statistics).
    void
    lap(double &phase);

    mesh::TetMesh           &mesh;
    physics::ParticleSystem &system;
    /// The local update of the mesh, masses and springs every sweep makes.
    physics::TopologyUpdate topology;
    double                 &integral_of_density;
    Parameters              parameters;
    Blade                   current;
    /// The stroke's decisions: crossings, sides, vertices on the cut.
    CrossingDecisions decisions;
    /// Typical edge length at rest (median), for the sub-division when nothing is active.
    double typical_edge = 0;
    /// FindTetraToCut: the cells a sweep meets and the cells the blade is in.
    SweepSearch search;
    /// The vertices of the cells the blade was in at the end of the last motion, with
    /// their positions then.
    std::vector<std::pair<unsigned int, Point>> blade_cell_positions;
    /// The children of the cells a sweep splits, and the copies of points on the cut.
    ChildBuilder children;
    /// The cells a sweep changes and how.
    CellSelection selection;
    /// The cells the last sweep added, and the split table's results for its cells.
    std::vector<unsigned int> added_ids;
    std::vector<SplitResult>  results;
    /// The end of the last lap().
    std::chrono::steady_clock::time_point lap_start;
    /// Where sweeps are recorded (set_recorder()), or nullptr.
    std::vector<CutRecord> *recorder = nullptr;
  };
} // namespace lacerta::cut
