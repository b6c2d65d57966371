#include <lacerta/base/exceptions.h>
#include <lacerta/mesh/tet_mesh.h>
#include <lacerta/physics/assembly.h>
#include <lacerta/physics/particle_ranges.h>
#include <lacerta/physics/particle_system.h>
#include <lacerta/physics/partitioned_tets.h>

#include <cmath>

namespace lacerta::physics
{
  namespace
  {
    /// The mesh of @p system, checked against its particles.
    const mesh::TetMesh &
    checked_mesh(const ParticleSystem &system)
    {
      if (system.mesh == nullptr)
        throw_error("A force model per tetrahedron needs the system's tetrahedra "
                    "(ParticleSystem::mesh), which were not given.");
      if (system.mesh->n_vertices() != system.n_particles())
        throw_error("A force model per tetrahedron: the mesh has ",
                    system.mesh->n_vertices(),
                    " vertices for ",
                    system.n_particles(),
                    " particles.");
      if (system.youngs_modulus == nullptr)
        throw_error("A force model per tetrahedron needs Young's modulus "
                    "(ParticleSystem::youngs_modulus), which was not given.");
      return *system.mesh;
    }
  } // namespace


  double
  checked_poisson_ratio(const ParticleSystem &system, const char *model)
  {
    const double nu = system.poisson_ratio;
    if (!(nu >= 0 && nu < 0.5))
      throw_error("Material/Poisson ratio = ",
                  nu,
                  ": the force model '",
                  model,
                  "' needs a Poisson ratio in [0, 0.5).");
    return nu;
  }


  void
  PartitionedTets::build(const ParticleSystem &system, const ParticleRanges &ranges)
  {
    const mesh::TetMesh &mesh = checked_mesh(system);
    parts.assign(ranges.n_parts(), Part());
    for (unsigned int t = 0; t < mesh.n_tets(); ++t)
    {
      const mesh::Tet &tet    = mesh.tet(t);
      const double     volume = mesh.volume(t);
      if (!(volume > 0))
      {
        const mesh::Point3 &a = mesh.vertex(tet[0]);
        throw_error("Force model: tetrahedron ",
                    t,
                    " (particles ",
                    tet[0],
                    ", ",
                    tet[1],
                    ", ",
                    tet[2],
                    ", ",
                    tet[3],
                    "; first vertex at rest (",
                    a[0],
                    ", ",
                    a[1],
                    ", ",
                    a[2],
                    ")) has rest volume ",
                    volume,
                    " m^3: it is inverted or flat, and has no rest shape.");
      }
      const double youngs =
        tet_stiffness_factor(mesh, t, *system.youngs_modulus) / volume;
      if (!(youngs > 0) || !std::isfinite(youngs))
        throw_error("Material/Youngs modulus: tetrahedron ",
                    t,
                    " gets E = ",
                    youngs,
                    " Pa at its centroid; Young's modulus must be positive and finite "
                    "on the object.");
      // D_m⁻¹ = (D_m⁻ᵀ)ᵀ, D_m's columns the edges from vertex 0 (det D_m = 6 V > 0).
      Matrix3 Dm;
      for (unsigned int i = 0; i < 3; ++i)
        for (unsigned int d = 0; d < 3; ++d)
          Dm[3 * d + i] = mesh.vertex(tet[i + 1])[d] - mesh.vertex(tet[0])[d];
      const Matrix3 inverse_t = inverse_transpose(Dm, determinant(Dm));
      Matrix3       rest_inverse;
      for (unsigned int r = 0; r < 3; ++r)
        for (unsigned int s = 0; s < 3; ++s)
          rest_inverse[3 * r + s] = inverse_t[3 * s + r];
      std::array<unsigned int, 4> part_of;
      for (unsigned int i = 0; i < 4; ++i)
        part_of[i] = ranges.part_of(tet[i]);
      for (unsigned int i = 0; i < 4; ++i)
      {
        // One copy per range, made at the first vertex that range owns.
        bool seen = false;
        for (unsigned int j = 0; j < i; ++j)
          seen |= part_of[j] == part_of[i];
        if (seen)
          continue;
        unsigned char owned = 0;
        for (unsigned int j = 0; j < 4; ++j)
          if (part_of[j] == part_of[i])
            owned |= static_cast<unsigned char>(1u << j);
        Part &part = parts[part_of[i]];
        for (unsigned int j = 0; j < 4; ++j)
          part.vertex[j].push_back(tet[j]);
        part.owned.push_back(owned);
        part.tet.push_back(t);
        part.rest_volume.push_back(volume);
        part.youngs_modulus.push_back(youngs);
        for (unsigned int k = 0; k < 9; ++k)
          part.rest_inverse[k].push_back(rest_inverse[k]);
      }
    }
  }


  std::vector<std::size_t>
  PartitionedTets::tets_per_particle(const ParticleSystem &system)
  {
    const mesh::TetMesh     &mesh = checked_mesh(system);
    std::vector<std::size_t> count(system.n_particles(), 0);
    for (const mesh::Tet &tet : mesh.get_tets())
      for (const unsigned int v : tet)
        ++count[v];
    return count;
  }
} // namespace lacerta::physics
