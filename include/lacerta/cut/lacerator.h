/**
 * @file
 * Lacerations (paper, Section 7): over-stretched surface springs tear the tissue along
 * a laceration surface, split with the cut's table by a virtual blade. See
 * doc/lacerations.md.
 */
#pragma once

#include <lacerta/cut/cut_record.h>
#include <lacerta/cut/cutter.h>
#include <lacerta/cut/geometry.h>
#include <lacerta/mesh/tet_mesh.h>

#include <deal.II/base/parameter_handler.h>

#include <array>
#include <cstdint>
#include <memory>
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
   * What one laceration check did: the heap's size and, if the tissue tore, the tear.
   */
  struct LacerationStatistics
  {
    /// Surface springs checked, and those above their maximum elongation (the heap).
    unsigned int surface_springs = 0, over_limit = 0;
    /// Whether a tear happened, and whether it continued an earlier one at its tip.
    bool torn = false, continued = false;
    /// The seed spring's particles and its elongation over its maximum.
    unsigned int seed_a = 0, seed_b = 0;
    double       seed_ratio = 0;
    /// Advances of the virtual blade, and whether the tear left the body (complete).
    unsigned int advances = 0;
    bool         complete = false;
    /// Tetrahedra replaced and created, particles created.
    unsigned int cut_tets = 0, created_tets = 0, new_particles = 0;
    /// Wall time of the tear (plane, blade and the cutter's updates), in seconds.
    double update_seconds = 0;
    /// The part of it spent finding the springs that cross the tear's plane.
    double search_seconds = 0;
    /// Whether the mesh changed (then the integrator must be re-initialised).
    bool changed = false;
    /// Particles the tear copied along its surface, (original, copy): constraints
    /// take over the copies of their particles (Scene::follow_cut()).
    std::vector<std::array<unsigned int, 2>> copied_particles;
  };

  /**
   * Checks the surface springs for over-elongation and tears the tissue (paper,
   * Section 7). Every step: the springs on boundary faces (including faces opened by
   * cuts and earlier tears) whose strain exceeds the material's maximum elongation go
   * into a heap ordered by strain over maximum; once the heap holds `Threshold h`
   * springs, a laceration starts at its root. The laceration surface is the plane
   * through the root's midpoint orthogonal to the mean direction of the over-stretched
   * springs near it; a virtual blade spanning the body's section across that plane
   * enters from the section's outline nearest to the root and advances while the
   * springs it is about to cross stay above `Propagation fraction` of their limit. The
   * blade drives a Cutter, so the split table, vertex duplication and the local
   * physics update are the cut's. doc/lacerations.md describes the rule.
   */
  class Lacerator
  {
  public:
    /// The laceration parameters (`subsection Laceration`).
    struct Parameters
    {
      unsigned int threshold            = 3;
      double       propagation_fraction = 0.5;
    };

    /// Declares `subsection Laceration`.
    static void
    declare_parameters(dealii::ParameterHandler &prm);

    /// Whether `Laceration/Enabled` is true.
    static bool
    enabled(dealii::ParameterHandler &prm);

    /// Reads `subsection Laceration`.
    static Parameters
    parse_parameters(dealii::ParameterHandler &prm);

    /**
     * Prepares lacerating @p mesh and @p system (masses and springs follow @p density
     * and @p youngs_modulus; @p integral_of_density is kept up to date), springs tearing
     * past @p maximum_elongation (a strain, evaluated at rest midpoints; a value outside
     * [0.001, 100] at a vertex is an Error naming `Material/Maximum elongation`).
     */
    Lacerator(mesh::TetMesh                     &mesh,
              physics::ParticleSystem           &system,
              const dealii::Function<3, double> &density,
              const dealii::Function<3, double> &youngs_modulus,
              const dealii::Function<3, double> &maximum_elongation,
              double                            &integral_of_density,
              const Cutter::Parameters          &cut_parameters,
              const Parameters                  &parameters);

    ~Lacerator();

    /**
     * Checks the surface springs at the current positions and tears if the threshold
     * is reached. Call once per time step; when the result has `changed`,
     * re-initialise the integrator and recompute the critical time step.
     */
    LacerationStatistics
    check();

    /**
     * Tells the lacerator that something else (the scalpel) changed the mesh: the
     * surface springs are collected again.
     */
    void
    mesh_changed();

    /**
     * Makes every cutter of a laceration, present and future, append a record of each
     * sweep to @p records (Cutter::set_recorder()), so that the Multi-Triangulation can
     * be split along the tears as along cuts (doc/mt-cutting.md); nullptr stops it.
     */
    void
    set_recorder(std::vector<CutRecord> *records);

    /**
     * Tells the lacerator that the particle system now lives on another mesh (the
     * object it was built with, refilled by a re-extraction of the level of detail), so
     * particle numbers changed. The surface springs are
     * collected again; the cutters of lacerations that stopped inside are dropped (a
     * continuation builds a new one at the tip, on the new mesh); a particle flagged in
     * @p created_by_cut (one entry per particle) is again one a laceration created if it
     * lies, at rest, within one band of a particle that laceration created — the
     * nearest such laceration (doc/lacerations.md).
     */
    void
    particles_replaced(const std::vector<std::uint8_t> &created_by_cut);

    /// Whether particle @p v is one a laceration created (found again after
    /// particles_replaced()); such particles' springs do not start tears.
    bool
    created_by_laceration(const unsigned int v) const
    {
      return v < sheet.size() && sheet[v] != static_cast<unsigned int>(-1);
    }

    /// Number of tears so far (a continued laceration counts each advance phase).
    unsigned int
    n_tears() const
    {
      return tears;
    }

    /// Writes or reads the state for a checkpoint (see lacerta::Archive).
    void
    serialize(Archive &archive);

  private:
    /// A spring on the surface, with its limit.
    struct SurfaceSpring
    {
      unsigned int a, b;
      double       rest_length, limit;
      /// A tetrahedron with the spring on one of its boundary faces.
      unsigned int tet;
    };

    /// A laceration surface: plane, directions of advance and across, and progress.
    struct Laceration
    {
      Point origin, normal, advance, across;
      /// Band width of one advance (the seed's length).
      double edge = 0;
      /// Where the front stopped and where the section ends, along `advance`.
      double stop = 0, end = 0;
      bool   complete = false;
      /// The section's extent along `across` (the blade spans it).
      double across_lo = 0, across_hi = 0;
      /// Its cutter while it may still continue (it stopped inside the body); dropped
      /// when the particle system is replaced, then built again at the tip.
      std::shared_ptr<Cutter> cutter;
      /// Rest positions of the particles it created (to find them again on a new mesh).
      std::vector<Point> created_rest;
    };

    /// A spring crossing a laceration plane: where (along `advance`) and its state.
    struct Crossing
    {
      Point        at;
      double       along;
      unsigned int a, b;
      /// The spring's index (the mesh's edge id), which orders the crossings.
      unsigned int spring;
    };

    /// The maximum elongation at rest point @p x, checked against its range.
    double
    limit_at(const Point &x) const;

    /// Collects the springs of the boundary faces and their limits.
    void
    collect_surface_springs();

    /// Strain over limit of the spring between @p a and @p b at the current positions.
    double
    ratio(unsigned int a, unsigned int b) const;

    /// Whether the spring with midpoint @p x lies next to the torn part of a laceration.
    bool
    in_wake(const Point &x) const;

    /**
     * The springs crossing the plane of @p l within the blade's extent, with their
     * positions along it, in spring order: the part of the section connected to
     * tetrahedron @p seed_tet (all springs if no tetrahedron near it crosses the
     * plane).
     */
    void
    find_crossings(const Laceration &l, unsigned int seed_tet);

    /// The blade of @p l when its front is at @p along.
    Blade
    blade_at(const Laceration &l, double along) const;

    /**
     * Advances the blade of laceration @p l from @p from while the springs ahead stay
     * above the propagation fraction (unconditionally up to @p forced); sets `l.stop`.
     */
    void
    advance(unsigned int l, double from, double forced, LacerationStatistics &s);

    /// A cutter for laceration @p l, its blade where the front is at @p along.
    std::shared_ptr<Cutter>
    make_cutter(const Laceration &l, double along);

    /// Starts a laceration at surface spring @p seed.
    void
    start(const SurfaceSpring &seed, LacerationStatistics &s);

    /// Current position of particle @p v.
    Point
    position(unsigned int v) const;

    mesh::TetMesh                     &mesh;
    physics::ParticleSystem           &system;
    const dealii::Function<3, double> &density;
    const dealii::Function<3, double> &youngs_modulus;
    const dealii::Function<3, double> &maximum_elongation;
    double                            &integral_of_density;
    Cutter::Parameters                 cut_parameters;
    Parameters                         parameters;

    std::vector<SurfaceSpring> surface;
    bool                       surface_valid = false;
    /// The heap of over-stretched surface springs: (ratio, index into `surface`).
    std::vector<std::pair<double, unsigned int>> heap;
    std::vector<Crossing>                        crossings;
    /// Working arrays of find_crossings(), kept between tears so that a walk touches
    /// only the section: per tetrahedron and per edge the last walk that reached it
    /// (and whether the edge crosses the plane within the blade's extent).
    std::vector<unsigned int> tet_walk, edge_walk;
    std::vector<std::uint8_t> edge_in_extent;
    std::vector<unsigned int> walk_queue, walk_ring, walk_next_ring;
    unsigned int              walk = 0;
    std::vector<Laceration>   lacerations;
    /// For every particle, the laceration that created it (or none).
    std::vector<unsigned int> sheet;
    unsigned int              tears = 0;
    /// Where the lacerations' cutters record their sweeps, or nullptr.
    std::vector<CutRecord> *recorder = nullptr;
    /// Mean rest length of the surface springs of the mesh as built.
    double typical_edge = 0;
  };
} // namespace lacerta::cut
