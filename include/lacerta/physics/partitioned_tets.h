/**
 * @file
 * The tetrahedra of a particle system, copied into the thread ranges of a force model.
 */
#pragma once

#include <lacerta/physics/matrix3.h>

#include <array>
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
  class ParticleRanges;
  class ParticleSystem;

  /**
   * Every tetrahedron of a system's mesh copied into each particle range that owns one
   * of its vertices, as a structure of arrays per range: the thread of a range
   * evaluates its copies and adds forces only to the vertices it owns (`owned`), so a
   * tetrahedron across ranges is evaluated once per range and no thread writes
   * another's memory. build() copies in the order of the mesh's tetrahedra; update()
   * replaces the copies of the tetrahedra a cut or a tear changed, locally.
   */
  class PartitionedTets
  {
  public:
    /// The tetrahedra of one range.
    struct Part
    {
      /// The particle of every local vertex of every copy.
      std::array<std::vector<unsigned int>, 4> vertex;
      /// Bit i set if local vertex i belongs to the range.
      std::vector<unsigned char> owned;
      /// The mesh tetrahedron of every copy.
      std::vector<unsigned int> tet;
      /// The rest volume of every copy (m^3).
      std::vector<double> rest_volume;
      /// Young's modulus at the centroid at rest of every copy (Pa), as the springs
      /// take it (tet_stiffness_factor()).
      std::vector<double> youngs_modulus;
      /// D_m⁻¹ of every copy (D_m: the edges from local vertex 0 at rest as columns),
      /// entry (r, s) in array 3 r + s.
      std::array<std::vector<double>, 9> rest_inverse;

      /// The deformation gradient F = D_s D_m⁻¹ of copy @p c at positions @p x.
      Matrix3
      deformation_gradient(const std::size_t c, const double *x) const
      {
        const double *x0 = x + 3 * vertex[0][c];
        Matrix3       Ds;
        for (unsigned int i = 0; i < 3; ++i)
        {
          const double *xi = x + 3 * vertex[i + 1][c];
          for (unsigned int d = 0; d < 3; ++d)
            Ds[3 * d + i] = xi[d] - x0[d];
        }
        Matrix3 F{};
        for (unsigned int r = 0; r < 3; ++r)
          for (unsigned int s = 0; s < 3; ++s)
            for (unsigned int k = 0; k < 3; ++k)
              F[3 * r + s] += Ds[3 * r + k] * rest_inverse[3 * k + s][c];
        return F;
      }

      /**
       * The nodal forces of copy @p c under the first Piola–Kirchhoff stress @p P:
       * -V0 P D_m⁻ᵀ on local vertices 1 to 3 (columns), minus their sum on vertex 0.
       */
      void
      nodal_forces(const std::size_t c, const Matrix3 &P, double (&force)[4][3]) const
      {
        for (unsigned int d = 0; d < 3; ++d)
          force[0][d] = 0;
        for (unsigned int i = 0; i < 3; ++i)
          for (unsigned int d = 0; d < 3; ++d)
          {
            double sum = 0;
            for (unsigned int k = 0; k < 3; ++k)
              sum += P[3 * d + k] * rest_inverse[3 * i + k][c];
            force[i + 1][d] = -rest_volume[c] * sum;
            force[0][d] -= force[i + 1][d];
          }
      }

      /// Adds the nodal forces of copy @p c under stress @p P (nodal_forces()) to
      /// @p f at the vertices the range owns.
      void
      add_owned_nodal_forces(const std::size_t c, const Matrix3 &P, double *f) const
      {
        double force[4][3];
        nodal_forces(c, P, force);
        for (unsigned int i = 0; i < 4; ++i)
          if (owned[c] & (1u << i))
          {
            double *target = f + 3 * vertex[i][c];
            for (unsigned int d = 0; d < 3; ++d)
              target[d] += force[i][d];
          }
      }

      /// The number of copies.
      std::size_t
      size() const
      {
        return tet.size();
      }
    };

    /**
     * Copies the tetrahedra of `system.mesh` into @p ranges, with their rest volumes,
     * rest shapes (D_m⁻¹) and `system.youngs_modulus` at their centroids. Throws an Error
     * naming the tetrahedron if one is not positively oriented at rest or its modulus is
     * not positive, and one naming the mismatch if the mesh has no vertex for every
     * particle.
     */
    void
    build(const ParticleSystem &system, const ParticleRanges &ranges);

    /**
     * The mesh changed locally since the last build() or update() (a cut, a tear):
     * every tetrahedron that changed has a vertex that is an end of one of the
     * springs @p changed (indices into `system.springs`; a changed tetrahedron
     * changes the stiffness of its edges' springs) or is appended. Replaces the copies
     * of every such tetrahedron whose vertices are not those copied, and copies the
     * appended ones; the ranges must be those of the last build() with the new
     * particles appended to the last range. Costs O(changed tetrahedra of the stars
     * of the springs' ends), not O(mesh). Throws as build() does. The copies are then
     * those build() would make, in another order (a removed copy's hole takes its
     * range's last copy, new copies are appended), so forces summed over them agree
     * with a fresh build() to rounding, not to the bit.
     */
    void
    update(const ParticleSystem            &system,
           const ParticleRanges            &ranges,
           const std::vector<unsigned int> &changed);

    /**
     * Whether the copies are spread so unevenly over the ranges (appended particles
     * join the last range) that the ranges should be split again.
     */
    bool
    unbalanced() const;

    /// The copies of range @p p.
    const Part &
    part(const unsigned int p) const
    {
      return parts[p];
    }

    /**
     * Calls @p visit(t, p, c) once for every tetrahedron t, with its copy c in the
     * range p that owns its local vertex 0, range by range.
     */
    template <typename Visit>
    void
    for_each_tet(const Visit &visit) const
    {
      for (unsigned int p = 0; p < parts.size(); ++p)
        for (std::size_t c = 0; c < parts[p].size(); ++c)
          if (parts[p].owned[c] & 1u)
            visit(parts[p].tet[c], p, c);
    }

    /**
     * Calls @p visit(t, p, c) for every tetrahedron t of @p list with one of its
     * copies, index c of range p (the copies of a tetrahedron are alike but for the
     * vertices they own).
     */
    template <typename Visit>
    void
    for_each_copy_of(const std::vector<unsigned int> &list, const Visit &visit) const
    {
      for (const unsigned int t : list)
        visit(t, copies[t][0].part, std::size_t(copies[t][0].index));
    }

    /// The number of tetrahedra of every particle (the load to balance ranges by).
    static std::vector<std::size_t>
    tets_per_particle(const ParticleSystem &system);

    /// Writes or reads the copies for a checkpoint (see lacerta::Archive).
    void
    serialize(Archive &archive);

  private:
    /// Where a copy is: its range and its index there.
    struct CopyRef
    {
      unsigned int part  = invalid;
      unsigned int index = invalid;
    };
    static constexpr unsigned int invalid = static_cast<unsigned int>(-1);

    /// Copies tetrahedron @p t of @p mesh into the ranges owning its vertices.
    void
    add_copies(const ParticleSystem &system,
               const ParticleRanges &ranges,
               unsigned int          t);

    /// Removes every copy of tetrahedron @p t (the last copy of its range moves into
    /// the hole).
    void
    remove_copies(unsigned int t);

    /// Whether the copies of @p t are of the mesh's tetrahedron @p t as it is now.
    bool
    copied_as_is(const ParticleSystem &system, unsigned int t) const;

    std::vector<Part> parts;
    /// The copies of every tetrahedron (at most one per range, four ranges at most).
    std::vector<std::array<CopyRef, 4>> copies;
    /// Per tetrahedron, the update() that last saw it (no tetrahedron visited twice).
    std::vector<unsigned int> seen;
    unsigned int              update_count = 0;
  };

  /**
   * `system.poisson_ratio`, checked to lie in [0, 0.5) for force model @p model (an
   * Error naming `Material/Poisson ratio` otherwise).
   */
  double
  checked_poisson_ratio(const ParticleSystem &system, const char *model);
} // namespace lacerta::physics
