/**
 * @file
 * The cutter: the scalpel's swept surface against the tissue, step by step (paper,
 * Sections 5.2 and 6), with the mesh and the particle system updated locally.
 */
#pragma once

#include <lacerta/cut/boundary_face_tree.h>
#include <lacerta/cut/cut_record.h>
#include <lacerta/cut/split_table.h>
#include <lacerta/cut/tool.h>
#include <lacerta/mesh/tet_mesh.h>

#include <deal.II/base/parameter_handler.h>

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
    /// re-initialisation (global: it repartitions the springs), in seconds.
    double update_seconds = 0, reinit_seconds = 0;
    /// Whether the mesh changed (then the integrator must be re-initialised).
    bool changed = false;
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

    /// The active tetrahedra A_t (those the blade is in).
    const std::vector<unsigned int> &
    active_tets() const
    {
      return active;
    }

  private:
    /// One sweep from the last applied crack front to @p end.
    void
    sweep(const Blade &end, CutStepStatistics &statistics);

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

    mesh::TetMesh                     &mesh;
    physics::ParticleSystem           &system;
    const dealii::Function<3, double> &density;
    const dealii::Function<3, double> &youngs_modulus;
    double                            &integral_of_density;
    Parameters                         parameters;
    Blade                              current;
    /// The crack front as last applied: the start of the next swept surface.
    Blade front;
    /// Typical edge length at rest (median), for the sub-division when nothing is active.
    double typical_edge = 0;
    /// Consecutive postponed sweeps.
    unsigned int n_postponed = 0;

    BoundaryFaceTree          tree;
    std::vector<unsigned int> active, next_active, candidates, queue;
    std::vector<unsigned int> tet_stamp, edge_stamp;
    unsigned int              stamp = 0;
    /// Vertices on the cut surface of the current stroke (progressive cuts).
    std::vector<std::uint8_t>           on_surface;
    std::vector<unsigned int>           on_surface_list;
    std::vector<BoundaryFaceTree::Face> hits;
    /// Where sweeps are recorded (set_recorder()), or nullptr.
    std::vector<CutRecord> *recorder = nullptr;
  };
} // namespace lacerta::cut
