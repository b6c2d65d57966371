/**
 * @file
 * "These cells leave, these cells arrive": the one local update of a mesh and its
 * particle system that cuts, tears and changes of the level of detail share.
 */
#pragma once

#include <lacerta/mesh/tet_mesh.h>
#include <lacerta/physics/assembly.h>

#include <array>
#include <optional>
#include <vector>

namespace lacerta::physics
{
  class ParticleSystem;

  /**
   * Replaces tetrahedra of a mesh and follows the change in the particle system whose
   * particles are the mesh's vertices, locally: the cells that go take their lumped
   * masses (Section 3.1) and their share of their edges' springs (E·V/|e|², Section
   * 3.2, or their fitted stiffnesses if ParticleSystem::fitted_springs) out, the mesh is
   * changed by TetMesh::replace_tets(), the springs follow the edges (appended, moved
   * into retired slots), the cells that come put their terms in, and particles left
   * without cells are removed. The springs changed since the last notify_force_model()
   * are then passed to the force model at once. The cost is proportional to the cells and
   * particles involved, never to the mesh.
   *
   * A change is made of these stages, in this order: take_out() of the cells that go
   * (while the mesh still has them), any new particles (the caller adds them to both
   * the mesh and the system), replace(), then remove_particles() of the vertices
   * left without cells, restore_spatial_order() (a change of the level of detail,
   * whose subscribers follow particle_renumbering()), and notify_force_model().
   */
  class TopologyUpdate
  {
  public:
    /**
     * Updates @p mesh (local updates are enabled) and @p system with the masses of
     * density @p density times @p mass_scale and the springs of Young's modulus
     * @p youngs_modulus, the rules compute_masses() and compute_springs() follow.
     */
    TopologyUpdate(mesh::TetMesh                     &mesh,
                   ParticleSystem                    &system,
                   const dealii::Function<3, double> &density,
                   const dealii::Function<3, double> &youngs_modulus,
                   double                             mass_scale = 1.0);

    /// Takes the terms of the cells @p removed out of their particles' masses and
    /// their edges' springs (before replace() removes them).
    void
    take_out(const std::vector<unsigned int> &removed);

    /**
     * Replaces the cells @p removed by @p added in the mesh (TetMesh::replace_tets(),
     * with boundary ids @p face_ids), makes the springs follow the edges and puts the
     * new cells' terms in. Returns the new cells' ids. Where the system keeps its
     * cells' stiffnesses (ParticleSystem::cell_stiffness), @p added_stiffness, if
     * given, holds those of the added cells (local edge order); otherwise they follow
     * the rule.
     */
    const std::vector<unsigned int> &
    replace(const std::vector<unsigned int>                &removed,
            const std::vector<mesh::Tet>                   &added,
            const std::vector<std::array<unsigned int, 4>> &face_ids,
            const std::vector<std::array<double, 6>>       *added_stiffness = nullptr);

    /**
     * Scales the masses the last replace() put in so that they equal those the last
     * take_out() took out plus the (lumped) masses the particles removed since still
     * held: the total mass stays what it was although the new cells cover a slightly
     * different volume (a coarser or finer boundary of a level of detail; Section
     * 3.1's total ∫σ is kept exactly). Call before notify_force_model().
     */
    void
    conserve_mass();

    /**
     * Removes the vertices @p dead (held by no cell any more) from the mesh and their
     * particles from the system (TetMesh::remove_vertices()); the springs of the
     * particles moved into the freed slots take their new ends. Returns
     * particle_renumbering().
     */
    const std::vector<unsigned int> &
    remove_particles(const std::vector<unsigned int> &dead);

    /**
     * If the particles' numbering has drifted far from the spatial order
     * (TetMesh::spatial_vertex_order()), the springs' ends lying a quarter further
     * apart in memory (TetMesh::index_spread()) than in that order, renumbers the
     * mesh's vertices and the system's particles along it, with the springs' ends;
     * notify_force_model() then prepares the force model for all springs, and every
     * particle counts as changed. particle_renumbering() includes it. Returns whether
     * it renumbered. Particles added at the end and moved into freed slots by local
     * changes scatter what is close in space over the threads' ranges, whose springs
     * across two ranges are evaluated twice; the order of a new mesh is restored then,
     * at the cost of one evaluation of the whole system.
     */
    bool
    restore_spatial_order();

    /**
     * The index of every particle the system held before this change's
     * remove_particles() (those the change added included) after it and any
     * restore_spatial_order(), or mesh::invalid_index for a removed one; empty from
     * take_out() until one of those two is called. Arrays by particle held elsewhere
     * follow it.
     */
    const std::vector<unsigned int> &
    particle_renumbering() const
    {
      return new_index;
    }

    /// Passes the springs changed since the last call to the system's force model
    /// (ParticleSystem::springs_changed()), or all of them after
    /// restore_spatial_order(); does nothing if none changed.
    void
    notify_force_model();

    /// The particles whose masses take_out() and replace() changed since
    /// clear_touched(), with repetitions.
    const std::vector<unsigned int> &
    touched_particles() const
    {
      return touched;
    }

    /// Empties touched_particles().
    void
    clear_touched()
    {
      touched.clear();
    }

    /// The mass put in minus the mass taken out since the update was made (kg).
    double
    mass_delta() const
    {
      return delta;
    }

    /// The rest volume put in minus the rest volume taken out since the update was
    /// made (m^3).
    double
    volume_delta() const
    {
      return volume_change;
    }

  private:
    /// A cell's lumped mass contributions (Section 3.1) and its stiffness factor E·V
    /// (Section 3.2).
    struct CellTerms
    {
      std::array<double, 4> mass;
      double                stiffness_factor;
    };

    /// The terms of cell @p t of the mesh as it is now.
    CellTerms
    cell_terms(unsigned int t) const;

    /**
     * Adds @p sign (+1 or -1) times cell @p t's terms to its particles' masses and
     * its edges' springs; where the system keeps its cells' stiffnesses, an added
     * cell takes @p given (the rule if null) and keeps it there.
     */
    void
    add_cell_terms(unsigned int t, double sign, const std::array<double, 6> *given);

    /// The rule's contributions of cell @p t to its edges' stiffnesses.
    std::array<double, 6>
    rule_stiffnesses(unsigned int t, const CellTerms &terms) const;

    mesh::TetMesh                           &mesh;
    ParticleSystem                          &system;
    const dealii::Function<3, double>       &density;
    const dealii::Function<3, double>       &youngs_modulus;
    double                                   mass_scale;
    std::optional<ConstantDensityMass>       constant_density_mass;
    std::optional<double>                    constant_youngs_modulus;
    mesh::TetMesh::Update                    update_of_mesh;
    std::vector<unsigned int>                added_ids, touched, changed_springs;
    std::vector<std::array<unsigned int, 2>> vertex_moves;
    /// See particle_renumbering().
    std::vector<unsigned int> new_index;
    /// Whether restore_spatial_order() renumbered the particles since
    /// notify_force_model().
    bool   renumbered = false;
    double delta = 0, volume_change = 0;
    /// The masses the last take_out() took out and the last replace() put in (kg).
    double taken_out = 0, put_in = 0;
    /// The lumped masses the particles removed since the last take_out() held (kg).
    double removed_mass = 0;
    /// With fitted springs or kept cell stiffnesses (whose cells can give an edge
    /// nothing): the token stiffness of an edge every cell dropped, 1e-6 of the
    /// stiffest spring when the update was made (N/m).
    double stiffness_floor = 0;
  };
} // namespace lacerta::physics
