/**
 * @file
 * One stiffness scale for the decimated cells of a Multi-Triangulation, so that its
 * coarsest mesh is, as a whole, the material of the input mesh (issue 17, item 2;
 * doc/multiresolution.md, "The material of a level of detail").
 */
#pragma once

#include <lacerta/mt/coarse_stiffness.h>
#include <lacerta/mt/multi_triangulation.h>

#include <string>

namespace lacerta::mt
{
  /**
   * What homogenized_coarse_scale() found.
   */
  struct HomogenizedScale
  {
    /// The factor on the rule's springs of every decimated tetrahedron.
    double scale = 1;
    /// Energy per volume of the input mesh's springs, summed over the six unit strains
    /// (J/m³ per unit strain squared).
    double fine_energy_density = 0;
    /// The same for the coarsest mesh with the rule's springs unscaled.
    double coarse_energy_density = 0;
    /// Linear solves on the coarsest mesh until its energy matched.
    unsigned int iterations = 0;
    /// Whether it was read from a cache file (cached_homogenized_coarse_scale()).
    bool loaded = false;
  };

  /**
   * The factor s on the springs of the tetrahedra the decimation made (those with a
   * destroyer) that gives the coarsest mesh of @p mt (the root's tetrahedra) the
   * energy density of the input mesh (the tetrahedra without a destroyer) under
   * uniform strain.
   *
   * For each mesh, and each of the six unit strains ε of an orthonormal basis of
   * symmetric tensors, the boundary vertices are displaced by ε x and the interior
   * vertices settle where the springs linearised at rest (K = Σ k n nᵀ, k from
   * @p rule) hold them; the energies ½ uᵀ K u are summed over the strains and divided
   * by the mesh's volume. This is the effective stiffness of each spring network,
   * relaxation across the whole mesh included: what makes the coarse network of
   * Section 3.2's springs softer (or stiffer) than the fine one is its own geometry
   * (cell shapes and their connections), not its size, so one factor, found on the
   * coarsest mesh by secant iterations, serves every level. Throws a lacerta::Error if
   * a network's interior is not held by its springs or no factor in [0.1, 10] matches.
   */
  HomogenizedScale
  homogenized_coarse_scale(const MultiTriangulation &mt, const EdgeStiffnessRule &rule);

  /**
   * homogenized_coarse_scale(), kept in the file @p file: read from it when it holds
   * the result for the same rule (a checksum of @p rule's stiffnesses on the input and
   * coarsest meshes' tetrahedra, which the MT's own cache key does not cover),
   * otherwise computed and written there (a temporary file renamed into place). An
   * empty @p file only computes; a file that cannot be read or written is recomputed
   * or left, not an error.
   */
  HomogenizedScale
  cached_homogenized_coarse_scale(const MultiTriangulation &mt,
                                  const EdgeStiffnessRule  &rule,
                                  const std::string        &file);
} // namespace lacerta::mt
