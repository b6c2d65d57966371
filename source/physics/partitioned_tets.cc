#include <lacerta/base/archive.h>
#include <lacerta/base/exceptions.h>
#include <lacerta/mesh/tet_mesh.h>
#include <lacerta/physics/assembly.h>
#include <lacerta/physics/particle_ranges.h>
#include <lacerta/physics/particle_system.h>
#include <lacerta/physics/partitioned_tets.h>

#include <algorithm>
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
    copies.assign(mesh.n_tets(), {});
    seen.assign(mesh.n_tets(), 0);
    update_count = 0;
    for (unsigned int t = 0; t < mesh.n_tets(); ++t)
      add_copies(system, ranges, t);
  }


  void
  PartitionedTets::update(const ParticleSystem            &system,
                          const ParticleRanges            &ranges,
                          const std::vector<unsigned int> &changed)
  {
    const mesh::TetMesh &mesh = checked_mesh(system);
    if (!mesh.has_local_updates() || ranges.n_parts() != parts.size())
    {
      build(system, ranges);
      return;
    }
    // Slots past the mesh's end (fewer cells came than went: the last ones filled the
    // freed slots, which are among the changed cells) lose their copies first.
    for (std::size_t t = mesh.n_tets(); t < copies.size(); ++t)
      remove_copies(static_cast<unsigned int>(t));
    const unsigned int known =
      static_cast<unsigned int>(std::min<std::size_t>(copies.size(), mesh.n_tets()));
    copies.resize(mesh.n_tets());
    seen.resize(mesh.n_tets(), 0);
    ++update_count;
    const auto visit = [&](const unsigned int t)
    {
      if (seen[t] == update_count)
        return;
      seen[t] = update_count;
      if (t < known && copied_as_is(system, t))
        return;
      remove_copies(t);
      add_copies(system, ranges, t);
    };
    const std::size_t n_springs = system.springs.size();
    for (const unsigned int s : changed)
      if (s < n_springs)
      {
        for (const unsigned int t : mesh.tets_of_vertex(system.springs.a[s]))
          visit(t);
        for (const unsigned int t : mesh.tets_of_vertex(system.springs.b[s]))
          visit(t);
      }
    for (unsigned int t = known; t < mesh.n_tets(); ++t)
      visit(t);
  }


  bool
  PartitionedTets::unbalanced() const
  {
    std::vector<std::size_t> loads;
    for (const Part &part : parts)
      loads.push_back(part.size());
    return ParticleRanges::unbalanced(loads);
  }


  bool
  PartitionedTets::copied_as_is(const ParticleSystem &system, const unsigned int t) const
  {
    const CopyRef &first = copies[t][0];
    if (first.part == invalid)
      return false;
    const Part      &part = parts[first.part];
    const mesh::Tet &tet  = system.mesh->tet(t);
    for (unsigned int i = 0; i < 4; ++i)
      if (part.vertex[i][first.index] != tet[i])
        return false;
    return true;
  }


  void
  PartitionedTets::remove_copies(const unsigned int t)
  {
    for (CopyRef &ref : copies[t])
    {
      if (ref.part == invalid)
        break;
      Part             &part = parts[ref.part];
      const std::size_t last = part.size() - 1;
      if (ref.index != last)
      {
        const auto move = [&](auto &array) { array[ref.index] = array[last]; };
        for (auto &array : part.vertex)
          move(array);
        move(part.owned);
        move(part.tet);
        move(part.rest_volume);
        move(part.youngs_modulus);
        for (auto &array : part.rest_inverse)
          move(array);
        for (CopyRef &other : copies[part.tet[ref.index]])
          if (other.part == ref.part && other.index == last)
            other.index = ref.index;
      }
      const auto pop = [](auto &array) { array.pop_back(); };
      for (auto &array : part.vertex)
        pop(array);
      pop(part.owned);
      pop(part.tet);
      pop(part.rest_volume);
      pop(part.youngs_modulus);
      for (auto &array : part.rest_inverse)
        pop(array);
      ref = CopyRef();
    }
  }


  void
  PartitionedTets::add_copies(const ParticleSystem &system,
                              const ParticleRanges &ranges,
                              const unsigned int    t)
  {
    const mesh::TetMesh &mesh   = *system.mesh;
    const mesh::Tet     &tet    = mesh.tet(t);
    const double         volume = mesh.volume(t);
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
    const double youngs = tet_stiffness_factor(mesh, t, *system.youngs_modulus) / volume;
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
    const Matrix3               inverse_t = inverse_transpose(Dm, determinant(Dm));
    std::array<unsigned int, 4> part_of;
    for (unsigned int i = 0; i < 4; ++i)
      part_of[i] = ranges.part_of(tet[i]);
    unsigned int n_copies = 0;
    for (unsigned int i = 0; i < 4; ++i)
    {
      // One copy per range, made at the first vertex that range owns.
      bool seen_range = false;
      for (unsigned int j = 0; j < i; ++j)
        seen_range |= part_of[j] == part_of[i];
      if (seen_range)
        continue;
      unsigned char owned = 0;
      for (unsigned int j = 0; j < 4; ++j)
        if (part_of[j] == part_of[i])
          owned |= static_cast<unsigned char>(1u << j);
      Part &part            = parts[part_of[i]];
      copies[t][n_copies++] = {part_of[i], static_cast<unsigned int>(part.size())};
      for (unsigned int j = 0; j < 4; ++j)
        part.vertex[j].push_back(tet[j]);
      part.owned.push_back(owned);
      part.tet.push_back(t);
      part.rest_volume.push_back(volume);
      part.youngs_modulus.push_back(youngs);
      for (unsigned int r = 0; r < 3; ++r)
        for (unsigned int s = 0; s < 3; ++s)
          part.rest_inverse[3 * r + s].push_back(inverse_t[3 * s + r]);
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


  void
  PartitionedTets::serialize(Archive &archive)
  {
    std::size_t n = parts.size();
    archive    &n;
    parts.resize(archive.size(n, 1));
    for (Part &part : parts)
      archive(part.vertex,
              part.owned,
              part.tet,
              part.rest_volume,
              part.youngs_modulus,
              part.rest_inverse);
    archive(copies, seen, update_count);
  }
} // namespace lacerta::physics
