/**
 * @file
 * The tetrahedra of a particle system, copied into the thread ranges of a force model.
 */
#pragma once

#include <array>
#include <vector>

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
   * another's memory. Copies keep the order of the mesh's tetrahedra.
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

      /// The number of copies.
      std::size_t
      size() const
      {
        return tet.size();
      }
    };

    /**
     * Copies the tetrahedra of `system.mesh` into @p ranges, with their rest volumes
     * and `system.youngs_modulus` at their centroids. Throws an Error naming the
     * tetrahedron if one is not positively oriented at rest or its modulus is not
     * positive, and one naming the mismatch if the mesh has no vertex for every
     * particle.
     */
    void
    build(const ParticleSystem &system, const ParticleRanges &ranges);

    /// The copies of range @p p.
    const Part &
    part(const unsigned int p) const
    {
      return parts[p];
    }

    /// The number of tetrahedra of every particle (the load to balance ranges by).
    static std::vector<std::size_t>
    tets_per_particle(const ParticleSystem &system);

  private:
    std::vector<Part> parts;
  };

  /**
   * `system.poisson_ratio`, checked to lie in [0, 0.5) for force model @p model (an
   * Error naming `Material/Poisson ratio` otherwise).
   */
  double
  checked_poisson_ratio(const ParticleSystem &system, const char *model);
} // namespace lacerta::physics
